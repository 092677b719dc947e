r"""
Archard wear: a contact datum that depends on the solution
==========================================================

A model of your own whose contact gap changes with the solution: a quasistatic Kelvin-Voigt
block with damage (model 2.2's body) is pressed onto a compliant foundation and dragged along
it; the foundation wears by Archard's law, and the worn depth :math:`w` opens the gap,

.. math::

   \dot w = k_w\, p_\nu\, |\dot u_\tau| \quad\text{on } \Gamma_C,\qquad
   g = g_0 + w,\qquad p_\nu = c_\nu\,(u\cdot\nu - g),
   \qquad \text{friction bound } \mu\, p_\nu \text{ (Coulomb)}.

The physics, as decided here: the wear removes foundation material under the body, so
:math:`w \ge 0` only grows and the normal penetration :math:`u\cdot\nu - g_0 - w` falls where
it acts (the body must sink further to carry its load). :math:`w` is a state field of the
model (a P1 Function, nonzero on :math:`\Gamma_C` only): declared in ``old_state``, hence
checkpointed, so a restart continues exactly, and bounded below by 0 (``state_bounds``). The
block stays pressed on the whole of :math:`\Gamma_C` (the load is compressive everywhere), so
the compliance is the linear law :math:`c_\nu(u\cdot\nu - g)` there; a node of
:math:`\Gamma_C` that lets go stops the run (this model does not treat separation). At each
step :math:`t_{n-1} \to t_n`:

(W1) the wear, explicit, at the nodes of :math:`\Gamma_C` (nodal quadrature):

.. math::

   w_n = w_{n-1} + k\, k_w\, p_\nu(u_{n-1}, w_{n-1})\, |v_{\tau,n-1}|,
   \qquad p_\nu(u, w) = c_\nu (u\cdot\nu - g_0 - w)_+;

(W2) the damage step of model 2.2 (obstacle inclusion in :math:`[\zeta_*, 1]`, explicit source);

(W3) the velocity :math:`v_n` with :math:`v_{n,x} = V` on the top, the second-kind inequality

.. math::

   (\mathcal{A}\varepsilon(v_n), \varepsilon(z - v_n))
   + (\zeta_{n-1}\Phi_L(\mathcal{B}\varepsilon(u_{n-1})), \varepsilon(z - v_n))
   + \int_{\Gamma_C} c_\nu\bigl((u_{n-1} + k v_n)\cdot\nu - g_0 - w_n\bigr)(z - v_n)\cdot\nu
   + j_n(z) - j_n(v_n) \ge L_n(z - v_n),

   j_n(z) = \int_{\Gamma_C} \mu\, p_\nu(u_{n-1}, w_n)\, |z_\tau|
   \quad(\texttt{blocks.coulomb\_friction\_bound} \text{ with the worn gap});

(W4) :math:`u_n = u_{n-1} + k v_n`.

The gap :math:`g_0 + w_n` enters (W3) twice, in the normal term and in the friction bound;
the friction solver evaluates the bound again at every solve (a bound of the state). The
physics checks: (W1) summed over the steps, the worn volume equals :math:`k_w` times the
time integral of :math:`\int_{\Gamma_C} p_\nu |v_\tau|` (the scheme's own quadrature, to
round-off); the foundation carries the load while the gap opens (:math:`\int_{\Gamma_C}
p_\nu = \int_{\Gamma_N} q`, to the solver's tolerance); and with the whole of
:math:`\Gamma_C` sliding at the drive's speed, the worn volume is Archard's
:math:`k_w N s` (load :math:`N`, slid distance :math:`s`).
"""

# %%
# The model
# ---------
import dataclasses
import os
from pathlib import Path

import numpy as np
import ufl
import dolfinx.fem.petsc  # noqa: F401  (fem.petsc.assemble_vector)
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

import damage_dolfinx as dd
from damage_dolfinx import blocks as b
from damage_dolfinx.geometries.rectangle import rectangle, side

#: the vertex rule on the segments of Gamma_C: a boundary integral of P1 fields becomes the
#: sum over the nodes of the lumped weight times the nodal values
NODAL = {"quadrature_rule": "GLL", "quadrature_degree": 1}


class BoundaryNodes:
    """The nodes of Gamma_C owned by this rank, with their lumped weights m_i = int phi_i ds:
    ``values(expr)`` gives a UFL expression of P1 fields at these nodes (its nodal integral
    against phi_i divided by m_i)."""

    def __init__(self, Z, dsC):
        self.Z, self.ds = Z, dsC(metadata=NODAL)
        self.phi = ufl.TestFunction(Z)
        self.owned = Z.dofmap.index_map.size_local
        m = self._assemble(fem.form(self.phi * self.ds))
        self.dofs = np.flatnonzero(m > 0)
        self.m = m[self.dofs]
        self._forms = {}

    def _assemble(self, form):
        vec = fem.petsc.assemble_vector(form)
        vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        out = vec.getArray().copy()[:self.owned]
        vec.destroy()
        return out

    def values(self, key, expr):
        if key not in self._forms:
            self._forms[key] = fem.form(expr * self.phi * self.ds)
        return self._assemble(self._forms[key])[self.dofs] / self.m

    def integral(self, f):
        """int_{Gamma_C} f ds of a P1 Function by the vertex rule, on every rank."""
        return self.Z.mesh.comm.allreduce(float(self.m @ f.x.array[self.dofs]), op=MPI.SUM)


class WearingKelvinVoigt(dd.Model):
    """Quasistatic Kelvin-Voigt body with damage on a wearing foundation (Archard), Coulomb
    friction; scheme (W1)-(W4) of the module docstring."""

    id = "kv-archard-wear"
    title = "quasistatic Kelvin-Voigt body, normal compliance with Archard wear and Coulomb friction"
    contact_roles = ("wear",)
    stability_limit = "explicit elastic term: k <= 2/m_visc"
    checkpoint_fields = ("u", "zeta", "v")
    old_state = (("u", "u_old"), ("zeta", "zeta_old"), ("w", "w_old"))  # w: checkpointed too
    update = ("u", "u_old", "v")                                       # (W4)
    state_bounds = {"w": (0.0, np.inf)}
    history_columns = ("wear_volume", "wear_power", "normal_force", "friction_its")
    contact_quadrature_degree = 2          # the pressure is P1 on Gamma_C: exact
    rules = {"k_w": (lambda v: v >= 0, "(wear coefficient) must be >= 0"),
             "mu": (lambda v: v >= 0, "(friction coefficient) must be >= 0"),
             "eps_reg": (lambda v: v > 0, "(friction regularisation) must be positive")}

    @classmethod
    def defaults(cls):
        p = dd.model_defaults("2.2")
        return dataclasses.replace(p, E=1000.0, extra={
            "m_visc": 10.0, "c_nu": 1e3, "mu": 0.3, "k_w": 1e-3, "gap0": 0.0,
            "drive": 1.0, "eps_reg": 1e-9})

    @classmethod
    def k_max(cls, params):
        return dd.model_class("2.2").k_max(params)  # the same explicit elastic term

    def __init__(self, data):
        super().__init__(data)
        p, x, msh = self.params, self.params.extra, self.mesh
        V, Z = b.vector_p1(msh), b.scalar_p1(msh)
        self.u, self.u_old, self.v = (fem.Function(V, name=s) for s in ("u", "u_old", "v"))
        self.zeta, self.zeta_old = fem.Function(Z, name="zeta"), fem.Function(Z, name="zeta_old")
        self.w, self.w_old = fem.Function(Z, name="wear"), fem.Function(Z, name="wear_old")
        self.k = data.time.k
        tags = data.geometry.facet_tags
        ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
        self.dsC, self.nu = ds(3), ufl.FacetNormal(msh)
        self.c_nu, self.gap0, self.k_w = x["c_nu"], x["gap0"], float(x["k_w"])
        self.damage = self.obstacle_damage_step()                                     # (W2)
        # (W3): the normal compliance implicit in v_n (linear: Gamma_C stays in contact)
        dv, z = ufl.TrialFunction(V), ufl.TestFunction(V)
        nu, c, k = self.nu, self.c_nu, self.k
        gap = self.gap()
        a = (ufl.inner(b.viscous_stress(dv, p.E, p.nu, x["m_visc"]), b.eps(z)) * ufl.dx
             + k * c * ufl.dot(dv, nu) * ufl.dot(z, nu) * self.dsC)
        l = (-ufl.inner(b.damaged_elastic_stress(self.u_old, self.zeta_old, p.E, p.nu,
                                                 p.L_trunc), b.eps(z)) * ufl.dx
             - c * (ufl.dot(self.u_old, nu) - gap) * ufl.dot(z, nu) * self.dsC
             + b.load(z, None, self.loads()[1], ds(2)))
        top = fem.locate_dofs_topological(V.sub(0), msh.topology.dim - 1, tags.find(2))
        drive = fem.dirichletbc(PETSc.ScalarType(x["drive"]), top, V.sub(0))
        g = b.coulomb_friction_bound(x["mu"], self.u_old, nu, c, gap)
        self.friction_problem = b.FrictionProblem(self.v, a, l, [drive], g, self.dsC,
                                                  self.context)
        self.friction = b.friction_solver("newton", self.friction_problem, x["eps_reg"],
                                          1.0, 100.0)
        # (W1) and the balances: the pressure and the slip rate at the nodes of Gamma_C
        self.nodes = BoundaryNodes(Z, self.dsC)
        self._tau = ufl.as_vector((-nu[1], nu[0]))
        Q = b.scalar_dg0(msh)
        self.von_mises = fem.Function(Q, name="von_mises")
        sigma = b.kelvin_voigt_stress(self.v, self.u, self.zeta, p.E, p.nu, x["m_visc"],
                                      p.L_trunc)
        self._vm = b.expression(b.von_mises(sigma), Q)
        self.output_fields = [self.u, self.v, self.zeta, self.w, self.von_mises]

    def gap(self):
        """The gap of (W3): g_0 + w_n, of the wear Function (so updated at every step)."""
        return self.gap0 + self.w

    def pressure(self, u, w):
        """p_nu(u, w) = c_nu (u.nu - g_0 - w)_+ (UFL)."""
        return b.normal_compliance_pressure(u, self.nu, self.c_nu, self.gap0 + w)

    def contact_pressure(self):
        return self.pressure(self.u, self.w)

    def slip_power(self, u, w, v):
        """p_nu(u, w) |v_tau| at the nodes of Gamma_C (the wear rate over k_w)."""
        return self.nodes.values(("power", id(u), id(w)),
                                 self.pressure(u, w) * abs(ufl.dot(v, self._tau)))

    def wear_step(self):                                                              # (W1)
        rate = self.k_w * self.slip_power(self.u_old, self.w_old, self.v)  # v: still v_{n-1}
        self.w.x.array[self.nodes.dofs] = self.w_old.x.array[self.nodes.dofs] + self.k * rate
        self.w.x.scatter_forward()

    def mechanics(self):
        its = self.friction.solve()                                                   # (W3)
        r = self.nodes.values("gap", ufl.dot(self.u_old + self.k * self.v, self.nu)
                              - self.gap0 - self.w)
        lowest = self.comm.allreduce(float(r.min()) if r.size else np.inf, op=MPI.MIN)
        if lowest < -1e-12 * max(1.0, abs(self.gap0)):
            raise b.ConvergenceError(f"{self.id}: Gamma_C lets go (penetration {lowest:.3g} < 0 "
                                     "at a node); this model keeps the whole contact closed")
        return its

    def scheme(self):
        return (dd.SubStep("wear", "update", "", self.wear_step),
                dd.SubStep("damage", "snes-vi", "damage_", self.damage.solve, ("damage_its",)),
                dd.SubStep("friction", "newton", "friction_", self.mechanics,
                           ("snes_its", "friction_its")))

    def scalars(self):
        power = self.slip_power(self.u, self.w, self.v)               # at t_n
        total = self.comm.allreduce(float(self.nodes.m @ power), op=MPI.SUM)
        return {**super().scalars(), "wear_volume": self.nodes.integral(self.w),
                "wear_power": total, "normal_force": -float(self.contact_resultant()[1])}

    def update_output(self):
        b.interpolate(self.von_mises, self._vm)


# %%
# The problem
# -----------
# A block :math:`(0, 1) \times (0, 0.25)` on the foundation (bottom, tag 3), its top (tag 2)
# pressed by a uniform :math:`q` (total :math:`N = q`) and dragged to the right at :math:`V = 1`
# (its top): it slides the distance :math:`s = V T` over the foundation. The friction on its
# bottom and the drive on its top make a moment that presses the leading edge harder.

Q_LOAD = 10.0


def block(comm, n):
    return rectangle(comm, (0.0, 0.0), (1.0, 0.25), 4 * n, n,
                     {2: side(1, 0.25), 3: side(1, 0.0)})


def make_problem(n=4, k=0.02, T=1.0, model=WearingKelvinVoigt, **params):
    return dd.Problem(model=model, mesh=block, n=n, T=T, k=k, name="wearing-block",
                      boundaries={"traction": 2, "wear": 3}, params=params,
                      traction=lambda x, t: ufl.as_vector((0.0, -Q_LOAD + 0.0 * x[0])))


problem = make_problem()
comm = MPI.COMM_WORLD


def profile(model):
    """(x, w, p) at the nodes of Gamma_C, gathered on every rank, sorted by x."""
    nodes = model.nodes
    X = nodes.Z.tabulate_dof_coordinates()[nodes.dofs, 0]
    p = nodes.values("p", model.contact_pressure())
    parts = comm.allgather(np.column_stack([X, model.w.x.array[nodes.dofs], p]))
    data = np.concatenate(parts)
    return data[np.argsort(data[:, 0])].T


def run_with_balances(problem, folder, keep=()):
    """The run step by step: the worn volume against k_w times the left Riemann sum of
    int p |v_tau| (the scheme's quadrature of (W1)), and the profiles at the steps ``keep``."""
    k_w, k = problem.parameters().extra["k_w"], problem.k
    power_sum, worst, profiles = 0.0, 0.0, {}
    with dd.steps(problem, folder, overwrite=True, progress=False, figures=False) as run:
        for step in run:
            scalars = step.model.scalars()
            volume = scalars["wear_volume"]
            worst = max(worst, abs(volume - k_w * power_sum) / max(volume, 1e-300))
            power_sum += k * scalars["wear_power"]
            if step.n in keep:
                profiles[step.t] = profile(step.model)
            last = step
    return worst, scalars, last, profiles


# %%
# Wear and the balances
# ---------------------
# The worn volume against :math:`k_w \sum_m k \int_{\Gamma_C} p_\nu |v_\tau|` (at every
# step), the foundation's force against the load at the end, and the worn volume against
# Archard's :math:`k_w N s` for the distance slid after the first step (the wear of a step
# uses the previous step's slip rate). Archard's number holds for a block that slides at the
# drive's speed everywhere: it does so after the elastic shear of the first steps (measured
# 0.7 % off; 2 % allowed). The two balances hold to round-off and to the solver's tolerance.

if __name__ == "__main__" or "DAMAGE_DOLFINX_DEMO_OUT" in os.environ:
    out = Path(os.environ.get("DAMAGE_DOLFINX_DEMO_OUT", "results")) / "wear"
    worst, final, last, profiles = run_with_balances(problem, out / "run",
                                                     keep=(2, 12, 25, 37, 50))
    x = problem.parameters().extra
    load = Q_LOAD
    imbalance = abs(final["normal_force"] - load) / load
    archard = x["k_w"] * load * x["drive"] * (problem.T - problem.k)
    archard_error = abs(final["wear_volume"] - archard) / archard
    if comm.rank == 0:
        print(f"worn volume {final['wear_volume']:.6e}, k_w N s = {archard:.6e}; "
              f"normal force {final['normal_force']:.10g}, load {load:g}")
        print(f"PHYSICS_CHECK wear_balance {worst:.3e} 1e-12 "
              f"{'PASS' if worst <= 1e-12 else 'FAIL'}")
        print(f"PHYSICS_CHECK load_balance {imbalance:.3e} 1e-8 "
              f"{'PASS' if imbalance <= 1e-8 else 'FAIL'}")
        print(f"PHYSICS_CHECK archard_volume {archard_error:.3e} 2e-2 "
              f"{'PASS' if archard_error <= 2e-2 else 'FAIL'}")
    assert worst <= 1e-12 and imbalance <= 1e-8 and archard_error <= 2e-2

    # %%
    # The wear profile
    # ----------------
    # The worn depth along :math:`\Gamma_C` grows fastest at the leading edge, where the
    # moment of friction and drive presses hardest. The block sinks and tilts into the worn
    # foundation: on this compliant foundation the opened gap is taken up by the body's motion,
    # and the pressure (below: after the first step with friction, dotted, and at the end,
    # dashed), fixed by the balance of forces and moments, hardly changes.
    if comm.rank == 0:
        import matplotlib.pyplot as plt
        fig, (ax, pax) = plt.subplots(2, 1, figsize=(6.0, 5.0), sharex=True,
                                      gridspec_kw={"height_ratios": [3, 2]})
        times = sorted(profiles)
        for i, t in enumerate(times):
            X, w, p = profiles[t]
            ax.plot(X, w, "-", color=plt.cm.viridis(i / max(len(times) - 1, 1)),
                    label=f"$t = {t:.2g}$")
        for t, style in ((times[0], ":"), (times[-1], "--")):
            X, w, p = profiles[t]
            pax.plot(X, p, style, color="C3", label=f"$t = {t:.2g}$")
        ax.set_ylabel("worn depth $w$")
        ax.set_ylim(bottom=0.0)
        ax.legend(fontsize=8, loc="upper left")
        ax.set_title("Archard wear under a block dragged to the right")
        pax.set_xlabel("$x$ along $\\Gamma_C$")
        pax.set_ylabel("pressure $p_\\nu$")
        pax.set_ylim(bottom=0.0)
        pax.legend(fontsize=8, loc="lower right")
        fig.tight_layout()
        fig.savefig(out / "wear_profile.png", dpi=120)
