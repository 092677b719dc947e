"""Section 2.4's elastic-viscoplastic body with damage on a normal-compliance foundation instead
of friction (beyond the thesis): the scheme (2.184)-(2.187) of Problem VP^{hk} with the
frictional increment inequality (2.187) replaced by an equation,

    (2') w = delta u_n in V:  k (B eps(w), eps(v)) + (p_nu((u_{n-1} + k w).nu - g), v.nu)_{Gamma_C}
                                = L_n(v) - (sigma_{n-1} + k Ghat_n, eps(v))      for all v in V,

p_nu(r) = c_nu r_+ (normal compliance, frictionless; V = {v = 0 on Gamma_D}), solved by
semismooth Newton (SNES, prefix ``mech_``). Steps (1) Ghat_n, (3) u_n and sigma_n and (4) the
damage obstacle step are those of :mod:`~damage_dolfinx.models.viscoplastic_2_4`, unchanged:
this class overrides only the increment step (:meth:`increment_step`), the contact pressure it
exerts, and what the friction solver reported. Prefixes: ``damage_``, ``mech_``.
"""
from __future__ import annotations

import dataclasses

import ufl
from dolfinx import fem

from damage_dolfinx.core.errors import InputError
from damage_dolfinx.core.tags import GAMMA_C, GAMMA_D
from damage_dolfinx.forms.contact import normal_compliance_pressure, normal_compliance_term
from damage_dolfinx.models.base import SubStep
from damage_dolfinx.models.viscoplastic_2_4 import ElastoViscoplasticFriction
from damage_dolfinx.numerics.boundary import clamped
from damage_dolfinx.numerics.friction import FRICTION_DEFAULTS
from damage_dolfinx.numerics.solvers import NonlinearSolver

#: the friction data of 2.4 that a frictionless foundation does not read
FRICTION_DATA = {"friction_law", "g_fric", "mu_f", "S_n", "coulomb_normal", *FRICTION_DEFAULTS}


class ElastoViscoplasticCompliance(ElastoViscoplasticFriction):
    """Problem VP^{hk} of Section 2.4 on a normal-compliance foundation (frictionless)."""

    id = "2.4-nc"
    title = ("quasistatic elastic-viscoplastic body, normal-compliance foundation "
             "(frictionless)")
    contact_roles = ("normal_compliance",)

    @classmethod
    def defaults(cls):
        """2.4's data without its friction data, with the foundation's stiffness c_nu and gap."""
        p = super().defaults()
        extra = {key: v for key, v in p.extra.items() if key not in FRICTION_DATA}
        return dataclasses.replace(p, extra={**extra, "c_nu": 1e4, "gap": 0.0})

    @classmethod
    def with_roles(cls, params, roles):
        return params  # one contact role: nothing to select

    def increment_step(self) -> SubStep:
        """(2'): the increment equation with the foundation's pressure, by Newton on the
        semismooth residual (its UFL derivative: c_nu times the indicator of penetration)."""
        if self.mesh.topology.dim != 2:
            raise InputError(f"model {self.id} is written for 2-D meshes (Gamma_C horizontal)")
        x = self.params.extra
        a, l = self.increment_forms(self.w)
        u_n = self.u_old + fem.Constant(self.mesh, self.k) * self.w
        F = a - l + normal_compliance_term(u_n, ufl.TestFunction(self.V),
                                           ufl.FacetNormal(self.mesh), float(x["c_nu"]),
                                           float(x["gap"]), self.ds(GAMMA_C))
        self.mech = NonlinearSolver(F, self.w, [clamped(self.V, self.tags, GAMMA_D)], "mech_",
                                    self.context)
        return SubStep("mech", "semismooth", "mech_", self._compliance, its=("mech_its",))

    def _compliance(self) -> int:
        self._rate()                                                       # (1)
        return self.mech.solve()                                           # (2')

    def contact_pressure(self):
        x = self.params.extra
        return normal_compliance_pressure(self.u, ufl.FacetNormal(self.mesh), float(x["c_nu"]),
                                          float(x["gap"]))

    def iteration_totals(self) -> dict:
        return {"damage_snes": self.damage.iterations, "mech_snes": self.mech.iterations}
