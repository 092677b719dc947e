"""Section 2.4: quasistatic elastic-viscoplastic body with damage, contact with Tresca friction
(P1: bilateral, g_fric) or simplified Coulomb friction (P2: prescribed normal stress S_n, bound
mu_f |S_n|), scheme (2.184)-(2.187) of Problem VP^{hk}:

    (1) Ghat_n = P_Q[(1 - zeta_{n-1}) Phi_L(sigma_{n-1})]                                (G, 2.4.3)
    (2) w = delta u_n in V: k (B eps(w), eps(v - w)) + j(v) - j(w)
              >= L_n(v - w) - (sigma_{n-1} + k Ghat_n, eps(v - w))                         (2.187)
    (3) u_n = u_{n-1} + k w;  sigma_n = sigma_{n-1} + k P_Q[B eps(w)] + k Ghat_n           (2.184)
    (4) zeta_n in K^h: damage obstacle step with phi_A(eps(u_{n-1}), zeta_{n-1})            (2.186)

P1: V = {v = 0 on Gamma_D, v.nu = 0 on Gamma_C}; P2: V = {v = 0 on Gamma_D} and the load
S_n (v.nu)_{Gamma_C}. sigma in Q^h (DG0 tensors). Step (2) by the friction solvers of
friction/ (Newton on Phi_eps, eps_reg = 1e-9, by default); step (4) SNES vinewtonrsls.
Prefixes: ``damage_``, ``friction_`` (``uzawa_``, ``pd_``).
"""
from __future__ import annotations


import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from damage_dolfinx.core.tags import GAMMA_C, GAMMA_D, GAMMA_N

from damage_dolfinx import compat
from damage_dolfinx.numerics.boundary import bilateral_plane_faces, clamped
from damage_dolfinx.forms.constitutive import eps, von_mises
from damage_dolfinx.forms.viscoplastic import increment_step_forms, stress_update, viscoplastic_rate
from damage_dolfinx.numerics.friction import FrictionProblem, iteration_counters, law, solver_from_parameters
from damage_dolfinx.numerics import bookkeeping
from damage_dolfinx.models.base import DAMAGE_A, Model, SubStep
from damage_dolfinx.numerics.friction import FRICTION_DEFAULTS, FRICTION_RULES
from damage_dolfinx.core.parameters import ModelParameters

FRICTION_LAWS = ("tresca", "coulomb")


class ElastoViscoplasticFriction(Model):
    """Problem VP^{hk} of Section 2.4 (P1 or P2 by ``friction_law``)."""

    id = "2.4"
    title = ("quasistatic elastic-viscoplastic body, Tresca (P1) or simplified Coulomb (P2) "
             "friction")
    contact_roles = ("tresca", "coulomb")
    stability_limit = "explicit viscoplastic term: k <= 2/(1 - zeta*)"
    checkpoint_fields = ("u", "zeta", "w", "sigma")
    history_columns = ("stress_Q", "slip_max", "zeta_min_x", "zeta_min_y")
    old_state = (("u", "u_old"), ("sigma", "sigma_old"), ("zeta", "zeta_old"))

    #: the rules of the model's own data (name -> (test, what it must be))
    rules = {
        **FRICTION_RULES,
        "friction_law": (lambda v: v in ("tresca", "coulomb"), "must be 'tresca' or 'coulomb'"),
        "coulomb_normal": (lambda v: v in ("free", "bilateral"), "must be 'free' or 'bilateral'"),
        "viscoplastic_sign": (lambda v: v in (1.0, -1.0),
                              "(sign of the viscoplastic function G) must be 1 or -1"),
        "stress_in_error": (lambda v: v in ("yes", "no"),
                            "(Section 2.4: ||sigma - sigma_hk||_Q in e_hk) must be yes or no"),
    }

    @classmethod
    def defaults(cls) -> ModelParameters:
        return ModelParameters(E=1000.0, nu=0.3, **DAMAGE_A, extra={
            "friction_law": "tresca", "g_fric": 5.0, "mu_f": 0.05, "S_n": 10.0,
            "coulomb_normal": "free", "viscoplastic_sign": 1.0, "stress_in_error": "yes",
            **FRICTION_DEFAULTS})

    @classmethod
    def k_max(cls, params) -> float:
        """The explicit viscoplastic rate Ghat = (1 - zeta) Phi_L(sigma) (2.184) multiplies the
        self-equilibrated stress by 1 + k sign (1 - zeta) per step: with the relaxing sign this
        is stable iff k (1 - zeta) <= 2, so k_max = 2/(1 - zeta*); with the thesis sign the
        continuous stress itself grows (by e^{k(1 - zeta)} per step) and the same bound keeps
        the scheme's growth factor below 3."""
        return 2.0 / (1.0 - params.zeta_star)

    @classmethod
    def with_roles(cls, params, roles) -> ModelParameters:
        """A ``tresca`` boundary selects P1, a ``coulomb`` one P2 (``friction_law``)."""
        if roles & {"tresca", "coulomb"}:
            return params.replace(friction_law="coulomb" if "coulomb" in roles else "tresca")
        return params

    def __init__(self, data):
        """The model from its parts, each one named: a variant overrides the part it changes
        (a 2.4 body on a normal-compliance foundation replaces only :meth:`increment_step`)."""
        super().__init__(data)
        self.k = data.time.k
        self.tags = data.geometry.facet_tags
        self.ds = ufl.Measure("ds", domain=self.mesh, subdomain_data=self.tags)
        self.spaces()
        self.explicit_updates()                      # (1) and (3)
        self.increment = self.increment_step()       # (2)
        # (4) damage obstacle step, source from step n-1 (variant A, no sigma dependence:
        # docs/models.md, section 2.4)
        self.damage = self.obstacle_damage_step()
        self.outputs()

    # -- the parts
    def spaces(self):
        """P1 displacement u, its increment w = (u_n - u_{n-1})/k and damage zeta; DG0 (Q^h)
        stresses sigma and the viscoplastic rate Ghat; the old state of the step."""
        msh = self.mesh
        self.V, Z, self.Q = compat.vector_p1(msh), compat.scalar_p1(msh), compat.tensor_dg0(msh)
        self.u, self.u_old = fem.Function(self.V, name="u"), fem.Function(self.V, name="u_old")
        self.w = fem.Function(self.V, name="du")  # delta u_n = (u_n - u_{n-1}) / k
        self.sigma = fem.Function(self.Q, name="sigma")
        self.sigma_old = fem.Function(self.Q, name="sigma_old")
        self.G_hat = fem.Function(self.Q, name="G_hat")
        self.zeta, self.zeta_old = fem.Function(Z, name="zeta"), fem.Function(Z, name="zeta_old")

    def explicit_updates(self):
        """(1) and (3): cell-wise (DG0) updates, exact projections onto Q^h."""
        p, x = self.params, self.params.extra
        self._G_expr = compat.expression(
            viscoplastic_rate(self.sigma_old, self.zeta_old, p.L_trunc, x["viscoplastic_sign"]),
            self.Q)
        self._sigma_expr = compat.expression(
            stress_update(self.sigma_old, self.w, self.G_hat, fem.Constant(self.mesh, self.k),
                          p.E, p.nu), self.Q)

    def increment_forms(self, w, S_n=None):
        """(a, l) of the increment step (2.187) without its contact term, in ``w`` (a trial
        function, or the increment itself for a nonlinear residual)."""
        p, msh = self.params, self.mesh
        f_B, f_N = self.loads()
        return increment_step_forms(w, ufl.TestFunction(self.V), self.sigma_old, self.G_hat,
                                    fem.Constant(msh, self.k), p.E, p.nu, f_B, f_N,
                                    self.ds(GAMMA_N), S_n, ufl.FacetNormal(msh),
                                    self.ds(GAMMA_C))

    def increment_step(self) -> SubStep:
        """(2): the increment second-kind VI with Tresca (P1) or simplified Coulomb (P2)
        friction, by a friction solver (prefix ``friction_``)."""
        msh, x, tags = self.mesh, self.params.extra, self.tags
        law = x["friction_law"]
        S_n = fem.Constant(msh, float(x["S_n"])) if law == "coulomb" else None
        a, l = self.increment_forms(ufl.TrialFunction(self.V), S_n)
        bcs = [clamped(self.V, tags, GAMMA_D)]
        if law == "tresca" or x["coulomb_normal"] == "bilateral":
            bcs += bilateral_plane_faces(self.V, tags, GAMMA_C)
        g = fem.Constant(msh, float(x["g_fric"] if law == "tresca" else x["mu_f"] * abs(x["S_n"])))
        self.friction_problem = FrictionProblem(self.w, a, l, bcs, g, self.ds(GAMMA_C),
                                                self.context)
        self.friction = solver_from_parameters(self.friction_problem, x, tags, GAMMA_D,
                                               self.data.id)
        return SubStep("friction", "newton", "friction_", self._friction, its=("snes_its",))

    def outputs(self):
        """The von Mises stress, ||sigma||_Q, the contact nodes and the error components."""
        msh, x = self.mesh, self.params.extra
        self.von_mises = fem.Function(compat.scalar_dg0(msh), name="von_mises")
        self._vm_expr = compat.expression(von_mises(self.sigma), self.von_mises.function_space)
        self._stress_sq = bookkeeping.PiecewiseConstantNorm(self.sigma)  # sigma_n: DG0
        self._contact_dofs = self._gamma_c_dofs(self.V, self.tags)
        self.output_fields = [self.u, self.zeta, self.von_mises, self.sigma]
        self.error_components = [("u", self.u, "V"), ("sigma", self.sigma, "L2"),
                                 ("zeta", self.zeta, "L2")]  # e_hk of Section 2.4.3
        if x.get("stress_in_error", "yes") == "no":  # e_hk without ||sigma||_Q
            self.error_components = [c for c in self.error_components if c[0] != "sigma"]
        self.timings = {"damage": 0.0, self.increment.name: 0.0, "stress": 0.0}

    @staticmethod
    def _gamma_c_dofs(V, tags):
        facets = tags.indices[tags.values == GAMMA_C]
        return fem.locate_dofs_topological(V, V.mesh.topology.dim - 1, facets)

    # -- the scheme
    # t = 0: u_0 = 0, sigma_0 = 0 (the shared initial state): the first step absorbs f_N(0)
    # (docs/models.md, 2.4)

    def scheme(self) -> tuple:
        """In the order of (2.184)-(2.187): the explicit updates (3) of u and sigma are the
        sub-step ``stress``, before the damage step (4) (which reads u_{n-1} and zeta_{n-1})."""
        return (self.increment,                                                 # (1), (2)
                SubStep("stress", "update", "", self._stress),
                SubStep("damage", "snes-vi", "damage_", self.damage.solve,          # (4)
                        its=("damage_its",)))

    def _friction(self) -> int:
        self._rate()                                                       # (1)
        return self.friction.solve()                                       # (2)

    def _rate(self):
        compat.interpolate(self.G_hat, self._G_expr)                       # (1)

    def _stress(self):
        self.u.x.array[:] = self.u_old.x.array + self.k * self.w.x.array  # (3)
        compat.interpolate(self.sigma, self._sigma_expr)                  # (3) sigma_n, DG0

    def update_output(self):
        compat.interpolate(self.von_mises, self._vm_expr)

    def scalars(self) -> dict:
        """Base scalars, ||sigma_n||_Q, the largest tangential displacement on Gamma_C and the
        location of the most damaged node (lowest zeta; the first on ties)."""
        out = super().scalars()
        out["zeta_min_x"], out["zeta_min_y"] = self._most_damaged_point()
        out["stress_Q"] = float(np.sqrt(self.comm.allreduce(self._stress_sq.local())))
        u1 = self.tangential_displacement()
        out["slip_max"] = float(self.comm.allreduce(np.abs(u1).max() if u1.size else 0.0,
                                                    op=MPI.MAX))
        return out

    def tangential_displacement(self):
        """|u_tau| at the owned and ghost contact nodes (the friction solver's nodes in 3-D;
        u_1 in 2-D, where Gamma_C is horizontal)."""
        if self.mesh.topology.dim == 3:
            return law.norm(self.friction.nodes.tangential(self.u))
        return self.u.x.array.reshape(-1, 2)[self._contact_dofs, 0]

    def _most_damaged_point(self):
        n_owned = self.zeta.function_space.dofmap.index_map.size_local
        z = self.zeta.x.array[:n_owned]
        if not hasattr(self, "_zeta_coords"):
            self._zeta_coords = self.zeta.function_space.tabulate_dof_coordinates()[:n_owned, :2]
        i = int(np.argmin(z)) if z.size else -1
        local = (float(z[i]), *map(float, self._zeta_coords[i])) if z.size else (np.inf, 0.0, 0.0)
        best = min(self.comm.allgather(local))  # lowest zeta, then lowest x, y: rank independent
        return (best[1], best[2]) if best[0] < 1.0 - 1e-12 else (np.nan, np.nan)  # none if undamaged

    def iteration_totals(self) -> dict:
        return {"damage_snes": self.damage.iterations, "friction": self.friction.iterations,
                "friction_solver": self.friction.name, **iteration_counters(self.friction)}
