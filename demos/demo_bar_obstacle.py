r"""
A fully damageable bar hitting an obstacle (model 3.3)
======================================================

A bar is driven by a uniform body force towards a deformable obstacle at a distance :math:`d`
from its end, hits it and is stopped. In the fully damageable model (model ``"3.3"``) the
damage weakens everything the material does, viscosity, elasticity and the contact pressure:

.. math::

   \rho\, \ddot u - \operatorname{div}\bigl(\zeta\,\mathcal{A}\,\varepsilon(\dot u)
   + \zeta\, \Phi_L(\mathcal{B}\,\varepsilon(u))\bigr) = f,
   \qquad -\sigma_\nu = \zeta\, c_\nu (u_\nu - d)_+ \ \text{on } \Gamma_C,

with the damage obstacle problem :math:`\zeta \in [\zeta_*, 1]`,
:math:`\dot\zeta - \kappa\Delta\zeta \ni \phi(\varepsilon(u), \zeta)`. As the end of the bar
damages, the obstacle holds it less firmly and the bar sinks deeper into it.

What to take away: how to drive a body onto an obstacle with a gap, the time step limit of an
explicit dynamic scheme, and three numbers that any such run must satisfy: the free flight
before the impact is exact, no damage grows while the bar is unstrained, and the obstacle only
pushes (its impulse is positive).
"""

# %%
# Mesh
# ----
# The bar :math:`(0, 2) \times (0, 0.25)`, 16 x 2 squares cut along the diagonal from their
# lower left to their upper right corner; facet tag 3 on the end :math:`x = 2`.

import os
from pathlib import Path

import numpy as np
import ufl
from mpi4py import MPI

import damage_dolfinx as dd
from damage_dolfinx.geometries.rectangle import rectangle, side

comm = MPI.COMM_WORLD
out = Path(os.environ.get("DAMAGE_DOLFINX_DEMO_OUT", "results")) / "bar_obstacle"
length, height = 2.0, 0.25
geometry = rectangle(comm, (0.0, 0.0), (length, height), 16, 2, {3: side(0, length)})

# %%
# Model
# -----
# :math:`f = (50, 0)`, :math:`\rho = 1`, :math:`E = 10^4`, obstacle stiffness
# :math:`c_\nu = 10^4` at :math:`d = 0.1`: the bar reaches it at
# :math:`t = \sqrt{2 d \rho / f} = 0.063`. Damage from the strain energy
# (:math:`\lambda_u = 2 \cdot 10^4`), no healing. The run is refused above the limit :math:`k_{\max}`
# of the explicit elastic and contact forces; :math:`k = 0.008` is about 0.6 of it here.

f1, rho, c_nu, d = 50.0, 1.0, 1e4, 0.1
problem = dd.Problem(
    model="3.3", mesh=geometry, T=0.4, k=0.008, name="bar-obstacle",
    boundaries={"normal_compliance": 3},
    body_force=lambda x, t: ufl.as_vector((f1, 0.0)),
    params={"E": 1e4, "nu": 0.3, "rho": rho, "m_visc": 100.0, "c_nu": c_nu, "gap": d,
            "lam_u": 2e4, "lam_D": 0.0, "kappa": 0.01})

# %%
# Run
# ---

summary = dd.run(problem, out, overwrite=True, progress=False)
if comm.rank == 0:
    print(f"{summary['status']}: {summary['steps_done']} steps on {comm.size} rank(s), "
          f"k / k_max = {summary['k_over_k_max']:.2f}, "
          f"min zeta = {summary['final']['zeta_min']:.4f}")

# %%
# Physics checks
# --------------
# * Free flight: before the impact the bar moves rigidly,
#   :math:`\|\dot u\|_{L^2} = (f_1/\rho)\, t \sqrt{|\Omega|}`, and stays undamaged
#   (:math:`\min \zeta = 1`: no strain, no source).
# * Impulse: the obstacle only pushes back, so the momentum at :math:`T` is at most that of
#   free flight, :math:`\rho \int_\Omega \dot u_1(T) \le f_1 |\Omega| T`. The momentum comes
#   from the final velocity (``fields_final.npz``), integrated exactly on this mesh with the
#   weights :math:`|Q|/6\,(2, 1, 1, 2)` on the corners of each square :math:`Q`.

history = None
if comm.rank == 0:
    history = np.genfromtxt(out / "history.csv", delimiter=",", names=True)
history = comm.bcast(history, root=0)
t, v = history["t"], history["v_L2"]
k = t[1] - t[0]
area = length * height
flight = (t > 0) & (t < np.sqrt(2 * d * rho / f1) - k)
free_flight = float(np.max(np.abs(v[flight] / (f1 / rho * t[flight] * np.sqrt(area)) - 1)))
flight_damage = float(np.max(1 - history["zeta_min"][flight]))

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
impulse = f1 * area * summary["t_final"] - momentum
checks = [("free_flight", free_flight, 1e-10), ("no_damage_in_flight", flight_damage, 1e-12),
          ("obstacle_pushes", max(-impulse, 0.0), 1e-12)]
if comm.rank == 0:
    print(f"impulse of the obstacle: {impulse:.4f} (free-flight momentum "
          f"{f1 * area * summary['t_final']:.4f}); deepest interpenetration "
          f"{history['penetration_max'].max():.4f}")
    for name, value, tol in checks:
        print(f"PHYSICS_CHECK {name} {value:.3e} {tol:.0e} {'PASS' if value <= tol else 'FAIL'}")
assert all(value <= tol for _, value, tol in checks), checks

# %%
# Figure
# ------
# The interpenetration of the bar's end into the obstacle and the smallest damage value: the
# first impact damages the end and the bar bounces off; at the second impact the end is
# damaged completely (:math:`\zeta = \zeta_*`), the contact pressure, scaled by :math:`\zeta`,
# almost vanishes, and the bar sinks into the obstacle.

if comm.rank == 0:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 3.8), constrained_layout=True)
    ax.plot(t, history["penetration_max"], "o-", ms=3, label=r"$\max (u_\nu - d)_+$")
    ax.set_xlabel("time $t$")
    ax.set_ylabel("interpenetration")
    right = ax.twinx()
    right.plot(t, history["zeta_min"], color="C3", label=r"$\min \zeta$")
    right.set_ylabel(r"$\min \zeta$", color="C3")
    ax.legend(loc="upper left")
    fig.savefig(out / "impact.png", dpi=120)
