r"""
A block sliding on a rough floor (model 3.2)
============================================

A block on a rough floor is pushed by a uniform body force :math:`f` larger than the floor can
hold: it slides and accelerates. The dynamic Kelvin-Voigt body with damage (model ``"3.2"``)

.. math::

   \rho\, \ddot u - \operatorname{div}\bigl(\mathcal{A}\,\varepsilon(\dot u)
   + \zeta\, \Phi_L(\mathcal{B}\,\varepsilon(u))\bigr) = f,

is in bilateral contact with the floor (:math:`u_\nu = 0`) with Tresca friction of bound
:math:`g`: :math:`|\sigma_\tau| \le g`, and :math:`\sigma_\tau = -g\, \dot u_\tau /
|\dot u_\tau|` where the block slips. While the whole contact face slips forward, the friction
on it is :math:`g` everywhere, and the momentum balance of the block gives

.. math::

   \frac{d}{dt} \int_\Omega \rho\, \dot u_1 \, dx = f_1 |\Omega| - g L,

with :math:`L` the length of the contact face. What to take away: the friction law of model 3.2
and a check of its stress :math:`|\sigma_\tau| = g` through the momentum of the block.
"""

# %%
# Mesh
# ----
# The block :math:`(0, 2) \times (0, 0.5)`, 16 x 4 squares cut along the diagonal from their
# lower left to their upper right corner; facet tag 3 on the bottom face.

import os
from pathlib import Path

import numpy as np
import ufl
from mpi4py import MPI

import damage_dolfinx as dd
from damage_dolfinx.geometries.rectangle import rectangle, side

comm = MPI.COMM_WORLD
out = Path(os.environ.get("DAMAGE_DOLFINX_DEMO_OUT", "results")) / "sliding_block"
width, height = 2.0, 0.5
geometry = rectangle(comm, (0.0, 0.0), (width, height), 16, 4, {3: side(1, 0.0)})

# %%
# Model
# -----
# :math:`f = (20, 0)` per unit volume, :math:`g = 5`, :math:`\rho = 1`, :math:`E = 10^4`:
# the net force is :math:`f_1 |\Omega| - g L = 20 - 10 = 10`. The stability limit of the
# explicit elastic force is :math:`k_{\max} \approx 0.02` on this mesh; :math:`k = 0.01` lies
# below the bound that needs no eigensolve (``k_max_lower_bound`` in ``summary.json``), 50 steps
# to :math:`T = 0.5`.

f1, g, rho = 20.0, 5.0, 1.0
problem = dd.Problem(
    model="3.2", mesh=geometry, T=0.5, k=0.01, name="sliding-block",
    boundaries={"tresca": 3},
    body_force=lambda x, t: ufl.as_vector((f1, 0.0)),
    params={"E": 1e4, "nu": 0.3, "rho": rho, "g_fric": g, "lam_u": 1e5})

# %%
# Run
# ---

summary = dd.run(problem, out, overwrite=True, progress=False)
if comm.rank == 0:
    # k_max itself where k lies above the bound that needs no eigensolve, else that bound
    limit = (f"k_max = {summary['k_max']:.4f}" if summary.get("k_max") is not None
             else f"k_max >= {summary['k_max_lower_bound']:.4f}")
    print(f"{summary['status']}: {summary['steps_done']} steps on {comm.size} rank(s), "
          f"{limit}, min zeta = {summary['final']['zeta_min']:.4f}")

# %%
# Physics check
# -------------
# The momentum at :math:`T` from the final velocity (``fields_final.npz``: the nodal values and
# their coordinates, on rank 0): on this mesh the integral of a piecewise linear field is exact
# with the weights :math:`|Q|/6\,(2, 1, 1, 2)` on the corners (lower left, lower right, upper
# left, upper right) of each square :math:`Q`. The balance predicts
# :math:`\rho \int_\Omega \dot u_1(T) = (f_1 |\Omega| - g L)\, T = 5`.

momentum = None
if comm.rank == 0:
    with np.load(out / "fields_final.npz") as data:
        xy, v1 = data["v_coords"].round(12), data["v"][:, 0]
    xs, ys = np.unique(xy[:, 0]), np.unique(xy[:, 1])
    grid = np.zeros((xs.size, ys.size))
    grid[np.searchsorted(xs, xy[:, 0]), np.searchsorted(ys, xy[:, 1])] = v1
    squares = np.diff(xs)[:, None] * np.diff(ys)[None, :]
    momentum = rho * float(np.sum(squares / 6 * (2 * grid[:-1, :-1] + grid[1:, :-1]
                                                 + grid[:-1, 1:] + 2 * grid[1:, 1:])))
momentum = comm.bcast(momentum, root=0)
T = summary["t_final"]
expected = (f1 * width * height - g * width) * T
deviation = abs(momentum / expected - 1)
tolerance = 1e-8
verdict = "PASS" if deviation <= tolerance else "FAIL"
if comm.rank == 0:
    print(f"momentum at T: {momentum:.10f} (balance: {expected:g})")
    print(f"PHYSICS_CHECK momentum_balance {deviation:.3e} {tolerance:.0e} {verdict}")
assert verdict == "PASS", deviation

# %%
# Figure
# ------
# The displacement of the block, :math:`\|u\|_{L^2} / \sqrt{|\Omega|}` from the history,
# against rigid sliding with the acceleration :math:`a = (f_1 |\Omega| - g L) / (\rho |\Omega|)`:
# :math:`a t^2 / 2`. The elastic deformation adds little.

if comm.rank == 0:
    import matplotlib.pyplot as plt

    history = np.genfromtxt(out / "history.csv", delimiter=",", names=True)
    area = width * height
    a = (f1 * area - g * width) / (rho * area)
    fig, ax = plt.subplots(figsize=(7, 3.8), constrained_layout=True)
    ax.plot(history["t"], history["u_L2"] / np.sqrt(area), "o", ms=3,
            label=r"$\|u\|_{L^2} / \sqrt{|\Omega|}$")
    ax.plot(history["t"], a * history["t"] ** 2 / 2, "k-", lw=1, label="rigid sliding $a t^2/2$")
    ax.set_xlabel("time $t$")
    ax.set_ylabel("displacement")
    ax.legend()
    fig.savefig(out / "displacement.png", dpi=120)
