r"""
A block dragged over a rough foundation (model 2.2)
===================================================

A viscoelastic block rests on a rough rigid foundation. Its left face is held, its right face
is pulled by a traction that grows in time. On the foundation :math:`\Gamma_C` the contact is
bilateral (:math:`u_\nu = 0`) with Tresca friction of bound :math:`g`:

.. math::

   |\sigma_\tau| \le g, \qquad
   |\sigma_\tau| < g \Rightarrow \dot u_\tau = 0, \qquad
   |\sigma_\tau| = g \Rightarrow \sigma_\tau = -g\,\frac{\dot u_\tau}{|\dot u_\tau|}.

The body is of Kelvin-Voigt type (model ``"2.2"``), with damage variant A:

.. math::

   \sigma = \mathcal{A}\,\varepsilon(\dot u) + \zeta\, \mathcal{B}\,\varepsilon(u), \qquad
   \dot\zeta - \kappa \Delta \zeta = \lambda_D\,\frac{1 - \eta_*(\zeta)}{\eta_*(\zeta)}
   - \frac{\lambda_u}{2}\,\Psi\bigl(\varepsilon(u)\bigr) - \lambda_w,

with :math:`\mathcal{A} = \mathcal{B}/m`. What to take away: the friction stress at a point of
the foundation rises with the pull until it reaches the bound :math:`g`, and stays there while
the block slips; it never exceeds it.
"""

# %%
# Mesh
# ----
# The block :math:`(0, 2) \times (0, 0.5)`, a structured grid of 16 x 4 squares cut in two
# triangles (:func:`damage_dolfinx.geometries.rectangle.rectangle`); facet tags 1 left face,
# 2 right face, 3 bottom face.

import os
from pathlib import Path

import numpy as np
import ufl
from mpi4py import MPI

import damage_dolfinx as dd
from damage_dolfinx.geometries.rectangle import rectangle, side

comm = MPI.COMM_WORLD
out = Path(os.environ.get("DAMAGE_DOLFINX_DEMO_OUT", "results")) / "dragged_block"
geometry = rectangle(comm, (0.0, 0.0), (2.0, 0.5), 16, 4,
                     {1: side(0, 0.0), 2: side(0, 2.0), 3: side(1, 0.0)})

# %%
# Model
# -----
# The pull :math:`(60\,t, 0)` on the right face reaches :math:`60` at :math:`T = 1`; the friction
# bound is :math:`g = 10`. A history row records, at the probe point :math:`(1.75, 0)` of the
# foundation, the horizontal displacement and the tangential stress (``builders={"probe":
# ...}``). The viscosity :math:`m = 40` makes the explicit elastic term stable up to
# :math:`k_{\max} = 2/m = 0.05`; :math:`k = 0.025` gives 40 steps.

g = 10.0
problem = dd.Problem(
    model="2.2", mesh=geometry, T=1.0, k=0.025, name="dragged-block",
    boundaries={"clamped": 1, "traction": 2, "tresca": 3},
    traction=lambda x, t: ufl.as_vector((60.0 * t, 0.0)),
    params={"E": 2000.0, "nu": 0.25, "g_fric": g, "m_visc": 40.0},
    builders={"probe": (1.75, 0.0)})

# %%
# Run
# ---

summary = dd.run(problem, out, overwrite=True, progress=False)
if comm.rank == 0:
    print(f"{summary['status']}: {summary['steps_done']} steps on {comm.size} rank(s), "
          f"min zeta = {summary['final']['zeta_min']:.4f}")

# %%
# Physics check
# -------------
# The friction bound: :math:`\max_t |\sigma_\tau| \le g` at the probe (up to the solver's
# tolerance), and at the end, when the probe slips, :math:`|\sigma_\tau| = g`.

history = None
if comm.rank == 0:
    history = np.genfromtxt(out / "history.csv", delimiter=",", names=True)
history = comm.bcast(history, root=0)
t, u1, tau = history["t"], history["probe_u1"], np.abs(history["probe_sigma_tau"])
excess = max(0.0, tau.max() / g - 1)
at_bound = abs(tau[-1] / g - 1)
# The contact outputs of the whole foundation (``history.csv``): where the block slides the
# friction traction is at the bound, so the friction resultant is :math:`-g` times the
# sliding length (``slip_length``; here all of :math:`\Gamma_C` but the node held by the
# clamp), and the foundation pushes no net load in :math:`x` beyond it.
friction, sliding = history["friction_force"][-1], history["slip_length"][-1]
slip_balance = abs(friction / (-g * sliding) - 1)
checks = [("friction_bound", excess, 1e-6), ("slip_at_bound", at_bound, 1e-3),
          ("friction_resultant", slip_balance, 1e-6)]
if comm.rank == 0:
    print(f"friction resultant at T: {friction:.10g} (-g x sliding length "
          f"{sliding:g} = {-g * sliding:g})")
if comm.rank == 0:
    print(f"max |sigma_tau| = {tau.max():.6f}, final |sigma_tau| = {tau[-1]:.6f} (g = {g:g})")
    for name, value, tolerance in checks:
        print(f"PHYSICS_CHECK {name} {value:.3e} {tolerance:.0e} "
              f"{'PASS' if value <= tolerance else 'FAIL'}")
assert all(value <= tolerance for _, value, tolerance in checks), checks

# %%
# Figure
# ------
# The tangential stress at the probe against time: it follows the pull, then stays at the
# bound :math:`g` while the probe slides (its displacement grows faster from then on).

if comm.rank == 0:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 3.6), constrained_layout=True)
    ax.plot(t, tau, "o-", ms=3, label=r"$|\sigma_\tau|$ at the probe")
    ax.axhline(g, color="k", ls="--", lw=1, label="friction bound $g$")
    ax.set_xlabel("time $t$")
    ax.set_ylabel(r"$|\sigma_\tau|$")
    right = ax.twinx()
    right.plot(t, u1, color="C3", lw=1)
    right.set_ylabel(r"probe displacement $u_1$", color="C3")
    ax.legend(loc="lower right")
    fig.savefig(out / "friction.png", dpi=120)
