"""A variant of a package model built from its parts: Section 2.4's elastic-viscoplastic body
on a normal-compliance foundation instead of friction. As a package model (2.4-nc) it is one
class overriding 2.4's increment step; written in a user's script from public names only, the
same class gives the same fields. Physics: the foundation carries the load. The body lies in a
corner (the foundation is its bottom and left sides, no clamp), pressed into it by a constant
traction on its top and right sides; the discrete equilibrium tested with the constant fields
says int_{Gamma_C} p nu ds = -(the applied force), exactly, at every step."""
import dataclasses

import numpy as np
import pytest
import ufl

import damage_dolfinx as dd
from damage_dolfinx.geometries.rectangle import rectangle

Q = (-20.0, -40.0)       # the traction on the top (length 1) and right (length 0.5) sides
FORCE = (1.5 * Q[0], 1.5 * Q[1])


def corner(comm, n):
    """(0, 1) x (0, 0.5): tag 3 (the foundation) bottom and left, tag 2 top and right."""
    return rectangle(comm, (0, 0), (1, 0.5), 2 * n, n,
                     {3: lambda x: np.isclose(x[1], 0.0) | np.isclose(x[0], 0.0),
                      2: lambda x: np.isclose(x[1], 0.5) | np.isclose(x[0], 1.0)})


def problem(model):
    # gap -1e-3: the body starts pressed into the foundation, so that its stiffness holds
    # the body from the first Newton iterate (there is no clamp)
    return dd.Problem(model=model, mesh=corner, n=6, T=0.2, k=0.02,
                      boundaries={"traction": 2, "normal_compliance": 3},
                      traction=lambda x, t: ufl.as_vector(Q),
                      params={"gap": -1e-3, "c_nu": 1e4, "lam_u": 5e4})


def user_variant():
    """The variant as a researcher writes it (docs/writing_a_model.md, "A variant of a package
    model"): public names only, tags by number."""
    from dolfinx import fem
    b = dd.blocks
    parent = dd.model_class("2.4")

    class OnAFoundation(parent):
        id = "mine-2.4-on-a-foundation"
        title = "2.4 on a normal-compliance foundation"
        contact_roles = ("normal_compliance",)

        @classmethod
        def defaults(cls):
            p = dd.model_defaults("2.4")
            friction = {"friction_law", "g_fric", "mu_f", "S_n", "coulomb_normal",
                        *b.FRICTION_DEFAULTS}
            extra = {k: v for k, v in p.extra.items() if k not in friction}
            return dataclasses.replace(p, extra={**extra, "c_nu": 1e4, "gap": 0.0})

        @classmethod
        def with_roles(cls, params, roles):
            return params

        def increment_step(self):
            x = self.params.extra
            a, l = self.increment_forms(self.w)
            u_n = self.u_old + fem.Constant(self.mesh, self.k) * self.w
            F = a - l + b.normal_compliance_term(u_n, ufl.TestFunction(self.V),
                                                 ufl.FacetNormal(self.mesh), float(x["c_nu"]),
                                                 float(x["gap"]), self.ds(3))
            self.mech = b.NonlinearSolver(F, self.w, [b.clamped(self.V, self.tags, 1)],
                                          "mech_", self.context)
            return dd.SubStep("mech", "semismooth", "mech_", self._compliance,
                              its=("mech_its",))

        def _compliance(self):
            self._rate()
            return self.mech.solve()

        def contact_pressure(self):
            x = self.params.extra
            return b.normal_compliance_pressure(self.u, ufl.FacetNormal(self.mesh),
                                                float(x["c_nu"]), float(x["gap"]))

        def iteration_totals(self):
            return {"damage_snes": self.damage.iterations, "mech_snes": self.mech.iterations}

    return OnAFoundation


def test_the_foundation_carries_the_load_at_every_step(tmp_path):
    summary = dd.run(problem("2.4-nc"), tmp_path / "run", progress=False, figures=False)
    assert summary["status"] == "completed"
    h = dd.read_run(tmp_path / "run").history
    for i, component in enumerate(("contact_force_x", "contact_force_y")):
        assert np.abs(h[component][1:] + FORCE[i]).max() <= 1e-8 * abs(FORCE[i]), component
    assert h["contact_length"][-1] == pytest.approx(1.5)   # both sides of the corner in contact
    assert h["contact_penetration"][-1] > 1e-3             # pressed in beyond the gap
    assert h["zeta_min"][-1] < 1.0                         # and it damages


def test_the_variant_in_a_users_script_equals_the_package_model(tmp_path):
    dd.run(problem("2.4-nc"), tmp_path / "package", progress=False, figures=False)
    dd.run(problem(user_variant()), tmp_path / "script", progress=False, figures=False)
    a = np.load(tmp_path / "package" / "fields_final.npz")
    b = np.load(tmp_path / "script" / "fields_final.npz")
    for name in ("u", "zeta"):
        assert np.array_equal(a[name], b[name]), name


def test_the_variant_reuses_its_parent_and_copies_nothing():
    """The variant's class defines only what it changes; 2.4's own constructor builds it."""
    from damage_dolfinx.models.viscoplastic_2_4 import ElastoViscoplasticFriction
    from damage_dolfinx.models.viscoplastic_compliance_2_4 import ElastoViscoplasticCompliance
    own = {name for name in vars(ElastoViscoplasticCompliance)  # Python's own dunders aside
           if not (name.startswith("__") and name.endswith("__"))}
    assert "__init__" not in own and "scheme" not in own and "spaces" not in own
    assert own <= {"id", "title", "contact_roles", "defaults", "with_roles", "increment_step",
                   "_compliance", "contact_pressure", "iteration_totals"}
    assert issubclass(ElastoViscoplasticCompliance, ElastoViscoplasticFriction)


def test_the_variant_passes_the_model_self_test(tmp_path):
    report = dd.check_model(problem("2.4-nc"), out=tmp_path, mpi=False)
    assert report.ok, str(report)
