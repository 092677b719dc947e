r"""
Stress relaxation of a viscoelastic bar with long memory (model 2.3)
====================================================================

A bar is clamped at one end and pressed at the other by a stiff foundation that has moved in
by :math:`d = 0.01`: the end is held at a fixed displacement. The viscoelastic body with long
memory of model ``"2.3"`` has the stress

.. math::

   \sigma(t) = \mathcal{B}\,\varepsilon(u(t))
   + \int_0^t a(t - s)\, \zeta(s)\, \Phi_L\bigl(\mathcal{B}\,\varepsilon(u(s))\bigr)\, ds,
   \qquad a(\tau) = a_0\, e^{-r \tau},

where :math:`\Phi_L` truncates at :math:`L` and the damage :math:`\zeta` weights the memory.
The foundation acts by normal compliance, :math:`-\sigma_\nu = c_\nu (u_\nu - g)_+`, with a
negative gap :math:`g = -d` and a stiff :math:`c_\nu = 10^{10}`.

With a negative kernel (:math:`a_0 < 0`) the memory relaxes the stress. While the displacement
is held and the material sound (:math:`\zeta = 1`, damage switched off), :math:`u` stays the
elastic solution and the stress decays by the closed form

.. math::

   \frac{\sigma(t)}{\sigma(0)} = 1 + \int_0^t a(s)\, ds
   = 1 + \frac{a_0}{r}\bigl(1 - e^{-r t}\bigr).

What to take away: how to set up a held-displacement test with a contact gap, how the memory
kernel shapes the relaxation, and that damage (which weights the memory by :math:`\zeta`)
slows it.
"""

# %%
# Mesh
# ----
# The bar :math:`(0, 4) \times (0, 1)`, 16 x 4 squares cut in two triangles; facet tags 1 at
# :math:`x = 0` (clamped), 2 at :math:`x = 4` (in contact with the foundation).

import os
from pathlib import Path

import numpy as np
from mpi4py import MPI

import damage_dolfinx as dd
from damage_dolfinx.geometries.rectangle import rectangle, side

comm = MPI.COMM_WORLD
out = Path(os.environ.get("DAMAGE_DOLFINX_DEMO_OUT", "results")) / "relaxation"


def bar(comm, n):
    return rectangle(comm, (0.0, 0.0), (4.0, 1.0), 4 * n, n, {1: side(0, 0.0), 2: side(0, 4.0)})


# %%
# Model
# -----
# The kernel :math:`a(\tau) = -0.8\, e^{-2 \tau}`: the stress relaxes to
# :math:`1 + a_0/r = 60\,\%` of its initial value. Two runs of 40 steps to :math:`T = 2`: one
# with the damage source switched off (:math:`\lambda_D = \lambda_u = \lambda_w = 0`,
# :math:`\zeta = 1` for all time), one with damage (:math:`\lambda_u = 10^5`).

a0, rate, d = -0.8, 2.0, 0.01


def relaxation(lam_u):
    return dd.Problem(
        model="2.3", mesh=bar, n=4, T=2.0, k=0.05, name=f"relaxation-lam_u-{lam_u:g}",
        boundaries={"clamped": 1, "normal_compliance": 2},
        params={"E": 1e4, "nu": 0.3, "lam_D": 0.0, "lam_u": lam_u, "lam_w": 0.0,
                "kappa": 0.01, "c_nu": 1e10, "gap": -d, "memory_kernel": "exponential",
                "memory_amplitude": a0, "memory_rate": rate})


# %%
# Run
# ---

runs = {}
for lam_u in (0.0, 1e5):
    summary = dd.run(relaxation(lam_u), out / f"lam_u_{lam_u:g}", overwrite=True,
                     progress=False)
    history = None
    if comm.rank == 0:
        history = np.genfromtxt(out / f"lam_u_{lam_u:g}" / "history.csv", delimiter=",",
                                names=True)
    runs[lam_u] = comm.bcast(history, root=0)
    if comm.rank == 0:
        print(f"lam_u = {lam_u:g}: {summary['status']}, {summary['steps_done']} steps on "
              f"{comm.size} rank(s), min zeta = {summary['final']['zeta_min']:.4f}")

# %%
# Physics check
# -------------
# Without damage the :math:`L^2` norm of the stress (history column ``stress_L2``) follows the
# closed form. The scheme adds the memory by the rectangle rule,
# :math:`M_n = \sum_{j=1}^n k\, a(t_n - t_{j-1})\, \sigma_{j-1}`, so the computed ratio is
# :math:`1 + \sum_{j=1}^n k\, a(t_n - t_{j-1})` up to the compliance of the foundation
# (:math:`E / c_\nu = 10^{-6}`), and differs from the integral by at most :math:`k |a_0|`.
# The decay is monotone.

t = runs[0.0]["t"]
k = t[1] - t[0]
ratio = {lam_u: h["stress_L2"] / h["stress_L2"][0] for lam_u, h in runs.items()}
exact = 1 + a0 / rate * (1 - np.exp(-rate * t))
rectangle_rule = np.array([1 + sum(k * a0 * np.exp(-rate * (tn - t[j - 1]))
                                   for j in range(1, n + 1)) for n, tn in enumerate(t)])
checks = [("rectangle_rule_sum", float(np.max(np.abs(ratio[0.0] - rectangle_rule))), 1e-5),
          ("relaxation_closed_form", float(np.max(np.abs(ratio[0.0] - exact))), k * abs(a0)),
          ("monotone_decay", max(float(np.max(np.diff(ratio[0.0]))), 0.0), 1e-10)]
if comm.rank == 0:
    print(f"stress ratio at T: {ratio[0.0][-1]:.4f} (closed form {exact[-1]:.4f}, rectangle "
          f"rule {rectangle_rule[-1]:.4f}), with damage {ratio[1e5][-1]:.4f}")
    for name, value, tol in checks:
        print(f"PHYSICS_CHECK {name} {value:.3e} {tol:.0e} {'PASS' if value <= tol else 'FAIL'}")
assert all(value <= tol for _, value, tol in checks), checks

# %%
# Figure
# ------
# Without damage the stress relaxes towards :math:`1 + a_0/r`. The damaged bar relaxes less
# and then its stress rises again: the memory is weighted by :math:`\zeta`, which keeps falling,
# so the relaxing part of the stress fades.

if comm.rank == 0:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 3.8), constrained_layout=True)
    ax.plot(t, exact, "k-", lw=1, label="closed form (no damage)")
    ax.plot(t, ratio[0.0], "o", ms=4, label=r"computed, no damage")
    ax.plot(t, ratio[1e5], "s", ms=3, color="C3", label=r"computed, $\lambda_u = 10^5$")
    ax.set_xlabel("time $t$")
    ax.set_ylabel(r"$\|\sigma(t)\|_{L^2} / \|\sigma(0)\|_{L^2}$")
    ax.legend()
    fig.savefig(out / "relaxation.png", dpi=120)
