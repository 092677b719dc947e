r"""
A block dropped on a deformable foundation (model 3.1)
======================================================

A viscoelastic block falls under gravity from a height :math:`d` above a deformable
foundation, hits it, and bounces. The dynamic Kelvin-Voigt model with damage (model ``"3.1"``),

.. math::

   \rho\, \ddot u - \operatorname{div}\bigl(\mathcal{A}\,\varepsilon(\dot u)
   + \zeta\, \Phi_L(\mathcal{B}\,\varepsilon(u))\bigr) = f,
   \qquad
   \dot\zeta - \kappa \Delta \zeta = \phi\bigl(\varepsilon(u), \zeta\bigr),

has on its bottom face the normal compliance :math:`-\sigma_\nu = c_\nu (u_\nu - d)_+`: the
foundation pushes back in proportion to how far the block has sunk into it. The time scheme
is explicit in the elastic and contact forces, so the time step must stay below a limit
:math:`k_{\max}` that depends on the mesh, :math:`E`, :math:`c_\nu` and :math:`\rho`: a
:class:`~damage_dolfinx.Problem` with a larger :math:`k` is refused with the value of
:math:`k_{\max}`, which :meth:`~damage_dolfinx.Problem.k_max` gives before the run.

What to take away: before the impact the block falls freely, :math:`v = g t`; at any time the
energy stored in the foundation, :math:`\frac{c_\nu}{2}\int_{\Gamma_C} (u_\nu - d)_+^2`, is
at most the work of gravity, :math:`m g` times the block's descent (the rest is kinetic
energy, elastic energy, or dissipated by viscosity and damage).
"""

# %%
# Mesh
# ----
# The block :math:`(0, 2) \times (0, 0.5)`, 16 x 4 squares cut in two triangles; facet tag 3
# on its bottom face. Nothing holds the block.

import os
from pathlib import Path

import numpy as np
import ufl
from mpi4py import MPI

import damage_dolfinx as dd
from damage_dolfinx.geometries.rectangle import rectangle, side

comm = MPI.COMM_WORLD
out = Path(os.environ.get("DAMAGE_DOLFINX_DEMO_OUT", "results")) / "impact"
width, height = 2.0, 0.5
geometry = rectangle(comm, (0.0, 0.0), (width, height), 16, 4, {3: side(1, 0.0)})

# %%
# Model
# -----
# Gravity :math:`g = 10`, density :math:`\rho = 1`, :math:`E = 10^4`, foundation stiffness
# :math:`c_\nu = 10^4` at the distance :math:`d = 0.2` below the block (the ``gap``). The
# contact begins at :math:`t = \sqrt{2 d / g} = 0.2`. No healing (:math:`\lambda_D = 0`).
#
# The time step: ``problem.k_max()`` gives the limit :math:`k_{\max}` of the explicit terms for
# this mesh and data before any run (a larger :math:`k` would be refused with its value); we
# run at about half of it.

g, rho, c_nu, d = 10.0, 1.0, 1e4, 0.2


def block(k):
    return dd.Problem(
        model="3.1", mesh=geometry, T=0.6, k=k, name="impact",
        boundaries={"normal_compliance": 3},
        body_force=lambda x, t: ufl.as_vector((0.0, -rho * g)),
        params={"E": 1e4, "nu": 0.3, "rho": rho, "m_visc": 10.0, "c_nu": c_nu, "gap": d,
                "lam_D": 0.0, "lam_u": 3e6})


k_max = block(None).k_max()  # the limit for this mesh and data, before any run
k = 0.0075
if comm.rank == 0:
    print(f"k_max = {k_max:.5g} (problem.k_max()); we run k = {k} = {k / k_max:.2f} k_max")
assert k < k_max
summary = dd.run(block(k), out, overwrite=True, progress=False)
if comm.rank == 0:
    print(f"{summary['status']}: {summary['steps_done']} steps of k = {k} "
          f"(k / k_max = {summary['k_over_k_max']:.2f}) on {comm.size} rank(s), "
          f"min zeta = {summary['final']['zeta_min']:.4f}")

# %%
# Physics checks
# --------------
# The history gives :math:`\|v\|_{L^2}`, :math:`\max |u|` over the nodes and the RMS
# penetration over :math:`\Gamma_C` (length :math:`L = 2`).
#
# * Free fall: while the block is in the air it moves rigidly, so
#   :math:`\|v\|_{L^2} = g t \sqrt{|\Omega|}` (the scheme integrates a constant acceleration
#   exactly).
# * Energy bound: :math:`\frac{c_\nu}{2} L\, \mathrm{rms}^2 \le m g \max|u|`, with
#   :math:`m = \rho |\Omega|`; the descent of the centre of mass is at most :math:`\max |u|`.

history = None
if comm.rank == 0:
    history = np.genfromtxt(out / "history.csv", delimiter=",", names=True)
history = comm.bcast(history, root=0)
t, v, u_max, rms = history["t"], history["v_L2"], history["u_max"], history["penetration_rms"]
area = width * height
in_air = (t > 0) & (t < np.sqrt(2 * d / g) - k)
free_fall = float(np.max(np.abs(v[in_air] / (g * t[in_air] * np.sqrt(area)) - 1)))
stored = 0.5 * c_nu * width * rms**2
work_bound = rho * area * g * u_max
ratio = float(np.max(stored[1:] / work_bound[1:]))
# * Momentum: the foundation's force (``contact_force_y``, a contact output of every model)
#   and gravity change the block's momentum :math:`\int_\Omega \rho v_y`: the scheme uses
#   the force of step :math:`n - 1` in step :math:`n`, so
#   :math:`\rho \int_\Omega v_y(T) = k \sum_{n<N} F_{y,n} - m g T`. The block bounces, it
#   is never at rest: this is the balance of the contact resultant and the load over the run.
#   :func:`damage_dolfinx.read_run` gives :math:`\int_\Omega v` at the last stored time.
mass = rho * area
impulse = k * history["contact_force_y"][:-1].sum() - mass * g * t[-1]
momentum = rho * dd.read_run(out).integral("v")[1]
momentum_balance = abs(impulse - momentum) / (mass * g * t[-1])
checks = [("free_fall", free_fall, 1e-10), ("energy_bound", max(ratio - 1, 0.0), 1e-12),
          ("momentum_balance", momentum_balance, 1e-8)]
if comm.rank == 0:
    print(f"contact impulse - m g T = {impulse:.10g}, final momentum = {momentum:.10g}; "
          f"contact force at T: {history['contact_force_y'][-1]:.6g} (weight m g = "
          f"{mass * g:g})")
if comm.rank == 0:
    print(f"largest share of the work of gravity stored in the foundation: {ratio:.3f} "
          f"(at t = {t[1:][np.argmax(stored[1:] / work_bound[1:])]:.4f})")
    for name, value, tol in checks:
        print(f"PHYSICS_CHECK {name} {value:.3e} {tol:.0e} {'PASS' if value <= tol else 'FAIL'}")
assert all(value <= tol for _, value, tol in checks), checks

# %%
# Figure
# ------
# The largest displacement (the descent of the block) against time: free fall to the
# foundation at :math:`u = d`, a short impact, and the bounce.

if comm.rank == 0:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 3.8), constrained_layout=True)
    ax.plot(t, u_max, "o-", ms=3, label=r"$\max |u|$")
    ax.plot(t, 0.5 * g * t**2, "k:", lw=1, label=r"free fall $g t^2 / 2$")
    ax.axhline(d, color="C3", ls="--", lw=1, label="foundation $d$")
    ax.set_ylim(0, 1.3 * d)
    ax.set_xlabel("time $t$")
    ax.set_ylabel("descent")
    ax.legend(loc="lower right")
    fig.savefig(out / "impact.png", dpi=120)
