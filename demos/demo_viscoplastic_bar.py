r"""
Creep of a damaging viscoplastic bar (model 2.4)
================================================

A bar under a constant tensile traction :math:`S` flows: in the elastic-viscoplastic model
``"2.4"`` the stress rate is the elastic one plus a viscoplastic rate that grows with the
damage,

.. math::

   \dot\sigma = \mathcal{B}\,\varepsilon(\dot u) + s\,(1 - \zeta)\, \Phi_L(\sigma),
   \qquad
   \dot\zeta - \kappa \Delta \zeta = \lambda_D\,\frac{1 - \eta_*(\zeta)}{\eta_*(\zeta)}
   - \frac{\lambda_u}{2}\,\Psi\bigl(\varepsilon(u)\bigr) - \lambda_w,

with :math:`\Phi_L` the truncation at :math:`L` and the sign :math:`s = -1` of a relaxing
material (parameter ``viscoplastic_sign``). Sound material (:math:`\zeta = 1`) is elastic; as
it damages, it creeps.

Only a quarter of a symmetric bar is meshed, with frictionless rollers on the symmetry planes
(the Tresca contact role with bound :math:`g = 0`). The bar is then statically determinate:
:math:`\sigma = S\, e_1 \otimes e_1` at every time, and the strain follows from the damage
alone,

.. math::

   \varepsilon_{11}(t) = \frac{S}{E} \Bigl(1 + \int_0^t \bigl(1 - \zeta(s)\bigr)\, ds\Bigr).

What to take away: how the stress update of model 2.4 keeps equilibrium while the body flows,
and how damage drives the viscoplastic flow.
"""

# %%
# Mesh
# ----
# The quarter bar :math:`(0, 4) \times (0, 1)`, 16 x 4 squares cut in two triangles; facet tags
# 1 at :math:`x = 0` and 3 at :math:`y = 0` (the symmetry planes), 2 at :math:`x = 4`.

import os
from pathlib import Path

import numpy as np
import ufl
from mpi4py import MPI

import damage_dolfinx as dd
from damage_dolfinx.geometries.rectangle import rectangle, side

comm = MPI.COMM_WORLD
out = Path(os.environ.get("DAMAGE_DOLFINX_DEMO_OUT", "results")) / "viscoplastic_bar"
length, height = 4.0, 1.0
geometry = rectangle(comm, (0.0, 0.0), (length, height), 16, 4,
                     {1: side(0, 0.0), 2: side(0, length), 3: side(1, 0.0)})

# %%
# Model
# -----
# :math:`E = 1000`, :math:`\nu = 0.3`, :math:`S = 20` from :math:`t = 0` on, damage driven by
# the strain (:math:`\lambda_u = 2000`, no healing :math:`\lambda_D = 0`), 40 steps to
# :math:`T = 1`. The explicit viscoplastic term is stable for :math:`k \le 2/(1 - \zeta_*)`.

E, nu, S = 1000.0, 0.3, 20.0
problem = dd.Problem(
    model="2.4", mesh=geometry, T=1.0, k=0.025, name="viscoplastic-bar",
    boundaries={"tresca": [1, 3], "traction": 2},
    traction=lambda x, t: ufl.as_vector((S, 0.0)),
    params={"E": E, "nu": nu, "g_fric": 0.0, "viscoplastic_sign": -1.0, "lam_u": 2000.0,
            "lam_D": 0.0, "kappa": 0.01})

# %%
# Run
# ---

summary = dd.run(problem, out, overwrite=True, progress=False)
if comm.rank == 0:
    print(f"{summary['status']}: {summary['steps_done']} steps on {comm.size} rank(s), "
          f"zeta at T: {summary['final']['zeta_min']:.4f}")

# %%
# Physics checks
# --------------
# The history gives :math:`\|\sigma\|_{L^2}` (column ``stress_Q``) and
# :math:`\|\varepsilon(u)\|_{L^2}`. With the uniform fields of the bar,
# :math:`\|\sigma\|_{L^2} = S \sqrt{|\Omega|}` and
# :math:`\|\varepsilon\|_{L^2} = \varepsilon_{11} \sqrt{(1 + \nu^2) |\Omega|}`.
#
# * Equilibrium: :math:`\|\sigma\|_{L^2} / (S \sqrt{|\Omega|}) = 1` at every step.
# * Creep: the scheme applies the load at the first step and then adds
#   :math:`k (1 - \zeta_{n-1}) S/E` per step, the rectangle rule of the integral above,
#   :math:`\varepsilon_{11}(t_n) = \frac{S}{E}\bigl(1 + \sum_{m=1}^{n-1} k (1 - \zeta_m)\bigr)`,
#   with :math:`\zeta_m` the (uniform) damage of the history.

history = None
if comm.rank == 0:
    history = np.genfromtxt(out / "history.csv", delimiter=",", names=True)
history = comm.bcast(history, root=0)
t, zeta = history["t"], history["zeta_mean"]
k = t[1] - t[0]
area = length * height
stress_ratio = history["stress_Q"][1:] / (S * np.sqrt(area))
eps11 = history["eps_u_L2"] / np.sqrt((1 + nu**2) * area)
creep = S / E * (1 + np.concatenate([[0.0], np.cumsum(k * (1 - zeta[1:-1]))]))
# The contact force the foundations exert (history column ``contact_force_x``, the resultant
# of the friction and of the bilateral reactions on :math:`\Gamma_C`) balances the pull
# :math:`S \cdot` height at every step: the body is at rest (quasistatic).
balance = float(np.max(np.abs(history["contact_force_x"][1:] / (S * height) + 1)))
if comm.rank == 0:
    print(f"contact resultant at T: {history['contact_force_x'][-1]:.10g} "
          f"(load -S height = {-S * height:g})")
checks = [("contact_balance", balance, 1e-8),
          ("equilibrium", float(np.max(np.abs(stress_ratio - 1))), 1e-8),
          ("uniform_damage", float(np.max(history["zeta_max"] - history["zeta_min"])), 1e-8),
          ("creep_closed_form", float(np.max(np.abs(eps11[1:] / creep - 1))), 1e-6)]
if comm.rank == 0:
    print(f"strain at T: {eps11[-1]:.6f} (elastic {S / E:.6f}, closed form {creep[-1]:.6f})")
    for name, value, tol in checks:
        print(f"PHYSICS_CHECK {name} {value:.3e} {tol:.0e} {'PASS' if value <= tol else 'FAIL'}")
assert all(value <= tol for _, value, tol in checks), checks

# %%
# Figure
# ------
# The strain creeps faster as the damage grows; the stress stays at :math:`S`.

if comm.rank == 0:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 3.8), constrained_layout=True)
    ax.plot(t[1:], eps11[1:] / (S / E), "o", ms=4, label=r"computed $\varepsilon_{11} E / S$")
    ax.plot(t[1:], creep / (S / E), "k-", lw=1, label="closed form")
    ax.plot(t, zeta, "-", color="C3", label=r"damage $\zeta$")
    ax.set_xlabel("time $t$")
    ax.set_ylabel(r"$\varepsilon_{11} E / S$ and $\zeta$")
    ax.legend()
    fig.savefig(out / "creep.png", dpi=120)
