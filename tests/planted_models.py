"""Small own models for the contract tests and the model self-test: the demo's compliant
Kelvin-Voigt body (a correct model) and variants, each with one planted mistake."""
import dataclasses

import numpy as np
import ufl
from dolfinx import fem

import damage_dolfinx as dd
from damage_dolfinx import blocks as b
from damage_dolfinx.geometries.rectangle import rectangle, side


class Compliant(dd.Model):
    """Model 2.2 with normal compliance on Gamma_C (demos/demo_own_model.py), plus a passive
    scalar field ``theta`` with its own explicit evolution theta_n = theta_{n-1} + k (2 - zeta)
    read from the previous step (a field of its own)."""
    id = "test-compliant"
    title = "compliant Kelvin-Voigt body with a field of its own"
    contact_roles = ("normal_compliance",)
    extra_roles = {"roller": 4}
    stability_limit = "explicit elastic term: k <= 2/m_visc"
    checkpoint_fields = ("u", "zeta", "v", "theta")
    history_columns = ("theta_max",)
    old_state = (("u", "u_old"), ("zeta", "zeta_old"), ("theta", "theta_old"))
    update = ("u", "u_old", "v")
    contact_quadrature_degree = 2
    mech_prefix = "mech_"
    poison_step = None       # the step at which theta becomes NaN (a planted mistake)

    @classmethod
    def defaults(cls):
        p = dd.model_defaults("2.2")
        return dataclasses.replace(p, extra={"m_visc": 10.0, "c_nu": 1e4, "gap": 0.0})

    @classmethod
    def k_max(cls, params):
        return dd.model_class("2.2").k_max(params)

    def __init__(self, data):
        super().__init__(data)
        p, x, msh = self.params, self.params.extra, self.mesh
        V, Z = b.vector_p1(msh), b.scalar_p1(msh)
        self.u, self.u_old, self.v = (fem.Function(V, name=s) for s in ("u", "u_old", "v"))
        self.zeta, self.zeta_old = fem.Function(Z, name="zeta"), fem.Function(Z, name="zeta_old")
        self.theta, self.theta_old = fem.Function(Z, name="theta"), fem.Function(Z, name="theta_old")
        k = data.time.k
        self.damage = self.obstacle_damage_step()
        tags = data.geometry.facet_tags
        ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
        dsC = ds(3, metadata={"quadrature_degree": self.contact_quadrature_degree})
        self.n_facet, self.c_nu, self.gap = ufl.FacetNormal(msh), x["c_nu"], x["gap"]
        w, v, nu_ = ufl.TestFunction(V), self.v, self.n_facet
        r = ufl.dot(self.u_old + k * v, nu_) - self.gap
        p_nu = self.c_nu * ufl.conditional(ufl.ge(r, 0.0), r, 0.0)
        F = (ufl.inner(b.viscous_stress(v, p.E, p.nu, x["m_visc"]), b.eps(w)) * ufl.dx
             + ufl.inner(b.damaged_elastic_stress(self.u_old, self.zeta_old, p.E, p.nu,
                                                  p.L_trunc), b.eps(w)) * ufl.dx
             + p_nu * ufl.dot(w, nu_) * dsC)
        f_B, f_N = self.loads()
        F = F - b.load(w, f_B, f_N, ds(2))
        bcs = [b.clamped(V, tags, 1)] + b.bilateral(V, tags, 4)
        self.mech = b.NonlinearSolver(F, self.v, bcs, "mech_", self.context)
        Q = b.scalar_dg0(msh)
        self.von_mises = fem.Function(Q, name="von_mises")
        sigma = b.kelvin_voigt_stress(v, self.u, self.zeta, p.E, p.nu, x["m_visc"], p.L_trunc)
        self._vm = b.expression(b.von_mises(sigma), Q)
        self.output_fields = [self.u, self.v, self.zeta, self.theta, self.von_mises]

    def _heat(self):
        k = self.data.time.k
        self.theta.x.array[:] = self.theta_old.x.array + k * (2.0 - self.zeta_old.x.array)
        if self.poison_step is not None and self.n >= self.poison_step:
            self.theta.x.array[0] = np.nan
        return None

    def scheme(self):
        return (dd.SubStep("damage", "snes-vi", "damage_", self.damage.solve, ("damage_its",)),
                dd.SubStep("heat", "update", "", self._heat),
                dd.SubStep("mech", "semismooth", self.mech_prefix, self.mech.solve,
                           ("snes_its",)))

    def scalars(self):
        owned = self.theta.x.array[:self.theta.function_space.dofmap.index_map.size_local]
        from mpi4py import MPI
        return {**super().scalars(),
                "theta_max": self.comm.allreduce(float(owned.max()), op=MPI.MAX)}

    def update_output(self):
        b.interpolate(self.von_mises, self._vm)


def block(comm, n):
    return rectangle(comm, (0.0, 0.0), (1.0, 0.25), 4 * n, n,
                     {4: side(0, 0.0), 2: side(1, 0.25), 3: side(1, 0.0)})


def problem(model=Compliant, **kw):
    args = dict(model=model, mesh=block, n=2, T=0.2, k=0.05, name="planted",
                boundaries={"roller": 4, "traction": 2, "normal_compliance": 3},
                traction=lambda x, t: ufl.as_vector((0.0, -120.0 * t * x[0] ** 2)))
    args.update(kw)
    return dd.Problem(**args)


def variant(name, **attrs):
    """A subclass of Compliant with ``attrs`` (the planted mistake)."""
    return type(name, (Compliant,), {"id": f"test-{name}", "__module__": __name__, **attrs})


class _DropsTheta(Compliant):
    def checkpoint_state(self):  # an override that leaves theta out
        return {"u": self.u, "zeta": self.zeta, "v": self.v}


#: the planted mistakes: name -> (model class, what a correct package says)
PLANTED = {
    "nan_in_own_field": variant("nan_in_own_field", poison_step=2),
    "field_not_checkpointed": variant("field_not_checkpointed",
                                      checkpoint_fields=("u", "zeta", "v")),
    "override_drops_field": type("override_drops_field", (_DropsTheta,),
                                 {"id": "test-override_drops_field", "__module__": __name__}),
    "old_state_without_zeta": variant("old_state_without_zeta",
                                      old_state=(("u", "u_old"), ("theta", "theta_old"))),
    "old_state_without_u": variant("old_state_without_u",
                                   old_state=(("zeta", "zeta_old"), ("theta", "theta_old")),
                                   update=None),
    "wrong_prefix": variant("wrong_prefix", mech_prefix="velocity_"),
    "update_names_nothing": variant("update_names_nothing", update=("u", "u_old", "w")),
    "dynamic_without_limit": variant("dynamic_without_limit", dynamic=True),
    "unknown_norm": variant("unknown_norm", error_components=property(
        lambda self: [("u", self.u, "H1"), ("zeta", self.zeta, "L2")])),
}


class _HiddenOldState(Compliant):
    """Reads theta_old, copied by itself (begin_step) and not declared: its checkpoint misses
    theta, which no declaration shows (the restart check sees it)."""
    old_state = (("u", "u_old"), ("zeta", "zeta_old"))
    checkpoint_fields = ("u", "zeta", "v")

    def begin_step(self):
        self.theta_old.x.array[:] = self.theta.x.array


class _RankDependent(Compliant):
    """theta depends on the rank count (a value of rank 0 only, not reduced)."""

    def _heat(self):
        super()._heat()
        self.theta.x.array[:] += 0.01 * self.comm.size
        return None


PLANTED.update({
    "hidden_old_state": type("hidden_old_state", (_HiddenOldState,),
                             {"id": "test-hidden_old_state", "__module__": __name__}),
    "scalar_without_column": variant("scalar_without_column", history_columns=()),
    "rank_dependent": type("rank_dependent", (_RankDependent,),
                           {"id": "test-rank_dependent", "__module__": __name__}),
})

#: the check of dd.check_model each planted mistake fails
FAILS = {"nan_in_own_field": "run", "override_drops_field": "contracts",
         "old_state_without_zeta": "contracts", "old_state_without_u": "contracts",
         "wrong_prefix": "prefixes", "update_names_nothing": "contracts", "unknown_norm": "contracts",
         "dynamic_without_limit": "stability_limit", "hidden_old_state": "restart",
         "scalar_without_column": "history_columns", "rank_dependent": "serial_vs_2_ranks"}
