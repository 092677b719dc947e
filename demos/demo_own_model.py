r"""
Your own model: Kelvin-Voigt with normal compliance
===================================================

A model is one class: it declares what it is (id, contact roles, checkpointed fields, history
columns, sub-steps, explicit update, stability limit, default data) and builds its unknowns and
solvers from the public building blocks of :mod:`damage_dolfinx.models.blocks`; the step itself is the
package's (old state copied, sub-steps in order, explicit update). Here model 2.2 (quasistatic
Kelvin-Voigt body with damage) with the Tresca friction of its contact boundary replaced by
normal compliance :math:`p_\nu(r) = c_\nu r_+`, written in this script, without touching the
package. The scheme, at each step :math:`t_{n-1} \to t_n`:

1. the damage step of 2.2 (obstacle inclusion in :math:`[\zeta_*, 1]`, explicit source);
2. the velocity :math:`v_n`, semismooth Newton on

.. math::

   (\mathcal{A}\varepsilon(v_n), \varepsilon(w))
   + (\zeta_{n-1}\Phi_L(\mathcal{B}\varepsilon(u_{n-1})), \varepsilon(w))
   + \int_{\Gamma_C} p_\nu\bigl((u_{n-1} + k v_n)\cdot\nu - g\bigr)\, w\cdot\nu
   = L_n(w),

3. :math:`u_n = u_{n-1} + k v_n`.

It then gets everything a catalogue model gets: a run folder, stepping in your script with a
monitor that stops the run, a restart, MPI, ``converge`` and ``sweep``. The physics check: the
contact resultant :math:`\int_{\Gamma_C} p_\nu \nu` balances the load.
"""

# %%
# The model
# ---------
import dataclasses
import os
from pathlib import Path

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

import damage_dolfinx as dd
from damage_dolfinx import blocks as b
from damage_dolfinx.geometries.rectangle import rectangle, side


class CompliantKelvinVoigt(dd.Model):
    """Model 2.2 with normal compliance on Gamma_C instead of Tresca friction."""

    id = "2.2-compliance"
    title = "quasistatic Kelvin-Voigt body, normal compliance"
    contact_roles = ("normal_compliance",)
    extra_roles = {"roller": 4}                 # u.nu = 0 on a face (a coordinate plane)
    stability_limit = "explicit elastic term: k <= 2/m_visc"
    checkpoint_fields = ("u", "zeta", "v")
    history_columns = ("contact_force",)
    update = ("u", "u_old", "v")                # (3) u_n = u_{n-1} + k v_n (after u -> u_old)
    contact_quadrature_degree = 2               # p_nu has kinks: one rule for all contact terms

    @classmethod
    def defaults(cls):
        p = dd.model_defaults("2.2")
        return dataclasses.replace(p, extra={"m_visc": 10.0, "c_nu": 1e4, "gap": 0.0})

    @classmethod
    def k_max(cls, params):
        return dd.model_class("2.2").k_max(params)  # the same explicit elastic term

    def __init__(self, data):
        super().__init__(data)
        p, x, msh = self.params, self.params.extra, self.mesh
        V, Z = b.vector_p1(msh), b.scalar_p1(msh)
        self.u, self.u_old, self.v = (fem.Function(V, name=s) for s in ("u", "u_old", "v"))
        self.zeta, self.zeta_old = fem.Function(Z, name="zeta"), fem.Function(Z, name="zeta_old")
        k = data.time.k
        self.damage = self.obstacle_damage_step()                        # (1)
        tags = data.geometry.facet_tags
        ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
        dsC = ds(3, metadata={"quadrature_degree": self.contact_quadrature_degree})
        self.n_facet, self.c_nu, self.gap = ufl.FacetNormal(msh), x["c_nu"], x["gap"]
        w, v, nu_ = ufl.TestFunction(V), self.v, self.n_facet
        r = ufl.dot(self.u_old + k * v, nu_) - self.gap
        p_nu = self.c_nu * ufl.conditional(ufl.ge(r, 0.0), r, 0.0)      # Jacobian 1 at r = 0
        F = (ufl.inner(b.viscous_stress(v, p.E, p.nu, x["m_visc"]), b.eps(w)) * ufl.dx
             + ufl.inner(b.damaged_elastic_stress(self.u_old, self.zeta_old, p.E, p.nu,
                                                  p.L_trunc), b.eps(w)) * ufl.dx
             + p_nu * ufl.dot(w, nu_) * dsC)                             # (2)
        f_B, f_N = self.loads()
        F = F - b.load(w, f_B, f_N, ds(2))
        bcs = [b.clamped(V, tags, 1)] + b.bilateral(V, tags, 4)
        self.mech = b.NonlinearSolver(F, self.v, bcs, "mech_", self.context)
        Q = b.scalar_dg0(msh)
        self.von_mises = fem.Function(Q, name="von_mises")
        sigma = b.kelvin_voigt_stress(v, self.u, self.zeta, p.E, p.nu, x["m_visc"], p.L_trunc)
        self._vm = b.expression(b.von_mises(sigma), Q)
        self.output_fields = [self.u, self.v, self.zeta, self.von_mises]

    def scheme(self):
        return (dd.SubStep("damage", "snes-vi", "damage_", self.damage.solve, ("damage_its",)),
                dd.SubStep("mech", "semismooth", "mech_", self.mech.solve, ("snes_its",)))

    def contact_pressure(self):
        return b.normal_compliance_pressure(self.u, self.n_facet, self.c_nu, self.gap)

    def scalars(self):
        return {**super().scalars(), "contact_force": float(self.contact_resultant()[1])}

    def update_output(self):
        b.interpolate(self.von_mises, self._vm)


# %%
# The problem
# -----------
# A block :math:`(0, 1) \times (0, 0.25)` on a compliant foundation (bottom, tag 3), held
# horizontally by a roller on its left side (tag 4), pressed by a traction
# :math:`(0, -3 q t x^2)` on its top (tag 2): the total load is :math:`q t`.

comm = MPI.COMM_WORLD
out = Path(os.environ.get("DAMAGE_DOLFINX_DEMO_OUT", "results")) / "own_model"
Q_LOAD = 40.0


def block(comm, n):
    return rectangle(comm, (0.0, 0.0), (1.0, 0.25), 4 * n, n,
                     {4: side(0, 0.0), 2: side(1, 0.25), 3: side(1, 0.0)})


problem = dd.Problem(
    model=CompliantKelvinVoigt, mesh=block, n=4, T=0.5, k=0.05, name="compliant-block",
    boundaries={"roller": 4, "traction": 2, "normal_compliance": 3},
    traction=lambda x, t: ufl.as_vector((0.0, -3.0 * Q_LOAD * t * x[0] ** 2)))

# %%
# Step by step, with a monitor
# ----------------------------
# The run folder is written as for any run; here the loop stops once the foundation carries
# more than 7.5 (a collective number: every rank stops at the same step).

for step in dd.steps(problem, out / "run", overwrite=True, progress=False, figures=False):
    force = -step.contact_resultant()[1]
    if force > 7.5:
        break
if comm.rank == 0:
    print(f"stopped at t = {step.t:.3g} (step {step.n}) with contact force {force:.4g}")

# %%
# Restart and the physics check
# -----------------------------
# ``restart`` continues the stopped run to T. At t = T the foundation carries the load:
# :math:`\int_{\Gamma_C} p_\nu \nu_y = -q T` (the roller takes no vertical force).

summary = dd.run(problem, out / "run", restart=True, progress=False, figures=False)
R = summary["final"]["contact_force"]
imbalance = abs(R - (-Q_LOAD * problem.T * 1.0)) / (Q_LOAD * problem.T)
if comm.rank == 0:
    print(f"{summary['status']} at t = {summary['t_final']:.3g}; contact force {R:.6g}, "
          f"load {-Q_LOAD * problem.T:.6g}")
    print(f"PHYSICS_CHECK contact_balance {imbalance:.3e} 1e-8 "
          f"{'PASS' if imbalance <= 1e-8 else 'FAIL'}")
assert imbalance <= 1e-8

# %%
# The force on the foundation
# ---------------------------
# The history of the run (its column ``contact_force``, declared by the model), across the
# stop and the restart, against the load :math:`q t`.

if comm.rank == 0:
    import csv

    import matplotlib.pyplot as plt
    with open(out / "run" / "history.csv") as f:
        rows = list(csv.DictReader(f))
    t = np.array([float(r["t"]) for r in rows])
    force = -np.array([float(r["contact_force"]) for r in rows])
    fig, ax = plt.subplots(figsize=(5.5, 3.4))
    ax.plot(t, Q_LOAD * t, "-", color="0.6", label="load $q\\,t$")
    ax.plot(t, force, "o", label=r"foundation: $-\int_{\Gamma_C} p_\nu \nu_y$")
    ax.axhline(7.5, ls=":", color="C3", label="the monitor's stop")
    ax.set_xlabel("time $t$")
    ax.set_ylabel("vertical force")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / "contact_force.png", dpi=120)

# %%
# Convergence and a sweep
# -----------------------
# Like any problem with a mesh family: errors against a finer reference, and the final
# contact force over two foundation stiffnesses.

study = dd.converge(problem, out / "converge", n=[1, 2], k=[0.05], ref_n=4, ref_k=0.05,
                    progress=False)
swept = dd.sweep(problem, out / "sweep", {"c_nu": [1e3, 1e4]}, progress=False, figures=False)
if comm.rank == 0:
    for row in study["errors"]:
        print(f"converge n = {row['n']}, k = {row['k']:g}: error {row['error']:.3e}")
    print(f"observed rate in h: {study['rates']['h_at_smallest_k']:.2f}")
    print(f"sweep over c_nu: {swept['completed']} of {swept['points']} points completed")
