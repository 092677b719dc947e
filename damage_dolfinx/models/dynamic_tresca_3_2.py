"""Section 3.2: dynamic Kelvin-Voigt body, bilateral contact with Tresca friction, damage by the
obstacle inclusion (variant A), scheme (3.94)-(3.96):

    (1) zeta_n in K^h:  (zeta_n - zeta_{n-1}, xi - zeta_n) + k kappa (grad zeta_n, grad(xi - zeta_n))
                        >= k (phi(eps(u_{n-1}), eta_*(zeta_{n-1})), xi - zeta_n)   (3.94), SNES vinewtonrsls
    (2) v_n in V:       (rho (v_n - v_{n-1})/k, w - v_n) + (A eps(v_n), eps(w - v_n)) + j(w) - j(v_n)
                        >= L_n(w - v_n) - (eta_*(zeta_{n-1}) Phi_L(B eps(u_{n-1})), eps(w - v_n))  (3.95)
    (3) u_n = u_{n-1} + k v_n                                                        (3.96)

V = {v = 0 on Gamma_D, v.nu = 0 on Gamma_C}; j(w) = int_{Gamma_C} g |w_tau| (nodal quadrature);
u_0 = v_0 = 0. Step (2) is the second-kind VI of friction/ with a mass term in ``a``, solved by
``friction_solver`` (newton | uzawa | penalty-duality; prefixes ``friction_``, ``uzawa_``,
``pd_``). The mass term makes ``a`` coercive without Gamma_D, but Uzawa's stopping test
(relative change in ||eps(.)||) cannot see rigid translations, so Uzawa is refused there.
phi_A already evaluates eta_*(zeta), so phi(eps, eta_*(zeta)) = phi_A(eps, zeta).
Convergence errors use the norm (3.109): ||u||_L2 + ||zeta||_L2.
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
from damage_dolfinx.forms.dynamic_tresca import total_stress, velocity_step_forms
from damage_dolfinx.numerics.friction import FrictionProblem, iteration_counters, law, solver_from_parameters
from damage_dolfinx.numerics.solvers import replace_default_option
from damage_dolfinx.numerics.stability import checked, estimate_stability
from damage_dolfinx.models.base import DAMAGE_A, Model, SubStep
from damage_dolfinx.numerics.friction import FRICTION_DEFAULTS, FRICTION_RULES
from damage_dolfinx.core.parameters import ModelParameters


class DynamicTresca(Model):
    """Problem VP^{hk} of Section 3.2.

    Builders (Problem.builders): ``friction_bound`` (x -> UFL g(x), default the constant
    ``g_fric``) and ``contact_faces`` ({name: marker x -> bool}): for each face the history gets
    ``u_tau_max_<name>``, the largest |u_tau| over its contact nodes (nodal values).
    """

    id = "3.2"
    title = "dynamic Kelvin-Voigt body, bilateral contact with Tresca friction"
    contact_roles = ("tresca",)
    dynamic = True
    checks_time_step = True  # k against its eigenvalue estimate (stability_check)
    stability_limit = "explicit elastic force (eigenvalue estimate)"
    checkpoint_fields = ("u", "zeta", "v")
    history_columns = ("friction_its",)  # + u_tau_max_<face> per contact face
    old_state = (("u", "u_old"), ("v", "v_old"), ("zeta", "zeta_old"))
    update = ("u", "u_old", "v")  # (3.96) u_n = u_{n-1} + k v_n

    #: the rules of the model's own data (name -> (test, what it must be))
    rules = {
        **FRICTION_RULES,
    }

    @classmethod
    def defaults(cls) -> ModelParameters:
        return ModelParameters(E=1e4, nu=0.3, **dict(DAMAGE_A, kappa=1.0, lam_D=0.0),
                               extra={"rho": 1.0, "m_visc": 100.0, "g_fric": 5.0,
                                      "stability_check": "error", **FRICTION_DEFAULTS})

    def __init__(self, data):
        super().__init__(data)
        p, msh, x = self.params, self.mesh, data.params.extra
        V, Z = compat.vector_p1(msh), compat.scalar_p1(msh)
        self.u, self.u_old = fem.Function(V, name="u"), fem.Function(V, name="u_old")
        self.v, self.v_old = fem.Function(V, name="v"), fem.Function(V, name="v_old")
        self.zeta, self.zeta_old = fem.Function(Z, name="zeta"), fem.Function(Z, name="zeta_old")
        self.k = data.time.k
        self.error_components = [("u", self.u, "L2"), ("zeta", self.zeta, "L2")]  # (3.109)

        # (1) damage obstacle step (3.94), explicit source. Its reduced systems are less
        # mass-dominated than in 3.3 (k kappa / h^2 = 0.5 at n = 128, k = 0.01, kappa = 0.003;
        # 164 with kappa = 1): CG preconditioned by incomplete Cholesky (block Jacobi per rank)
        # instead of Jacobi, unless the user chose -damage_pc_type (a few times fewer CG
        # iterations and a cheaper damage step; benchmarks/README.md, "Why the defaults")
        self.damage = self.obstacle_damage_step()
        replace_default_option("damage_pc_type", "bjacobi")
        replace_default_option("damage_sub_pc_type", "icc")
        self.damage.snes.snes.setFromOptions()

        # (2) velocity second-kind VI (3.95): inertia, viscosity and friction implicit
        tags = data.geometry.facet_tags
        ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
        f_B, f_N = self.loads()
        a, l = velocity_step_forms(ufl.TrialFunction(V), ufl.TestFunction(V), self.v_old,
                                   self.u_old, self.zeta_old, float(x["rho"]), self.k, p.E, p.nu,
                                   x["m_visc"], p.L_trunc, p.zeta_star, f_B, f_N, ds(GAMMA_N))
        self.bcs = [clamped(V, tags, GAMMA_D)] + bilateral_plane_faces(V, tags, GAMMA_C)
        g_builder = data.builders.get("friction_bound")
        g = g_builder(ufl.SpatialCoordinate(msh)) if g_builder else fem.Constant(msh, x["g_fric"])
        self.friction_problem = FrictionProblem(self.v, a, l, self.bcs, g, ds(GAMMA_C),
                                                self.context)
        self.friction = solver_from_parameters(self.friction_problem, x, tags, GAMMA_D,
                                               data.id)
        self._faces_setup(data.builders.get("contact_faces") or {})
        self.k_max = self._stability_check(V, x)

        Q = compat.scalar_dg0(msh)
        self.von_mises = fem.Function(Q, name="von_mises")
        sigma = total_stress(self.v, self.u, self.zeta, p.E, p.nu, x["m_visc"], p.L_trunc,
                             p.zeta_star)
        self._vm_expr = compat.expression(von_mises(sigma), Q)
        self.output_fields = [self.u, self.v, self.zeta, self.von_mises]
        self.timings = {"damage": 0.0, "friction": 0.0}

    # -- the scheme
    def scheme(self) -> tuple:
        return (SubStep("damage", "snes-vi", "damage_", self.damage.solve,         # (3.94)
                        its=("damage_its",)),
                SubStep("friction", "newton", "friction_", self.friction.solve,    # (3.95)
                        its=("snes_its", "friction_its")))

    def update_output(self):
        compat.interpolate(self.von_mises, self._vm_expr)

    # -- stability of the explicit elastic force (docs/models.md, section 3.2)
    def _stability_check(self, V, x):
        """k_max of the explicit elastic term (stability.py), checked against k according to
        ``stability_check`` (warn | error | off); None when off. m_visc = 100 gives
        k_max just above 2/m_visc = 0.02 (docs/models.md, "Stability of the explicit terms")."""
        action = x.get("stability_check", "warn")
        if action == "off":
            return None
        p = self.params  # Tresca adds no explicit stiffness: c_nu = 0; eta_* Phi_L only lowers B
        out = estimate_stability(V, p.E, p.nu, float(x["rho"]), float(x["m_visc"]), c_nu=0.0,
                                 bcs=self.bcs, k=self.k)
        where = f"{self.data.id}: explicit elastic force, eigenvalue estimate"
        checked(out, self.k, where, action)
        self.k_max_lower_bound = out.get("k_max_lower_bound")
        return None if out["k_max"] is None else float(out["k_max"])

    @classmethod
    def declared_columns(cls, problem, dim: int) -> list:
        """friction_its and u_tau_max_<face> per face of ``builders["contact_faces"]``."""
        faces = problem.builders.get("contact_faces") or {}
        return ["friction_its"] + [f"u_tau_max_{name}" for name in faces]

    # -- the tangential displacement on named contact faces (Example 2: top vs bottom)
    def _faces_setup(self, faces: dict):
        nodes = self.friction.nodes  # owned contact nodes with their unit tangents
        X = self.v.function_space.tabulate_dof_coordinates()[nodes.dofs].T
        self._faces = {name: np.flatnonzero(marker(X)) for name, marker in faces.items()}
        self.extra_history_columns = self.declared_columns(self.data, self.mesh.topology.dim)

    def u_tau_max(self) -> dict:
        """max |u_tau| over the contact nodes of each named face (collective)."""
        u_tau = law.norm(self.friction.nodes.tangential(self.u))  # |u_tau| (3-D: a vector)
        local = np.array([u_tau[i].max() if i.size else 0.0 for i in self._faces.values()])
        glob = np.empty_like(local)
        self.comm.Allreduce(local, glob, op=MPI.MAX)
        return {f"u_tau_max_{name}": float(val) for name, val in zip(self._faces, glob)}

    def scalars(self) -> dict:
        return {**super().scalars(), **self.u_tau_max()}

    def iteration_totals(self) -> dict:
        return {"damage_snes": self.damage.iterations, "friction": self.friction.iterations,
                "friction_solver": self.friction.name, **iteration_counters(self.friction)}

    def summary_extra(self) -> dict:
        out = {} if self.k_max is None else {"k_max": self.k_max}
        if getattr(self, "k_max_lower_bound", None) is not None:
            out["k_max_lower_bound"] = self.k_max_lower_bound  # no eigensolve: k below it
        return out
