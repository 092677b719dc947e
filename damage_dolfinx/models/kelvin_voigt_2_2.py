"""Section 2.2: quasistatic Kelvin-Voigt body, bilateral contact with Tresca friction, damage
by the obstacle inclusion (variant A), scheme (2.66)-(2.68):

    (1) zeta_n in K^h:  (zeta_n - zeta_{n-1}, xi - zeta_n) + k kappa (grad zeta_n, grad(xi - zeta_n))
                        >= k (phi_A(eps(u_{n-1}), zeta_{n-1}), xi - zeta_n)     SNES vinewtonrsls [zeta*, 1]
    (2) v_n in V:       (A eps(v_n), eps(w - v_n)) + j(w) - j(v_n)
                        >= L_n(w - v_n) - (zeta_{n-1} Phi_L(B eps(u_{n-1})), eps(w - v_n))   (2.67)
    (3) u_n = u_{n-1} + k v_n                                                   (2.68)

V = {v = 0 on Gamma_D, v.nu = 0 on Gamma_C}; j(w) = int_{Gamma_C} g |w_tau| (nodal quadrature).
The dimension comes from the mesh: in 3-D B is isotropic 3-D elasticity, w_tau a
vector of the tangent plane of Gamma_C (faces parallel to coordinate planes).
Step (2) by one of the three friction solvers (damage_dolfinx/numerics/friction/), chosen by the parameter
``friction_solver`` (newton | uzawa | penalty-duality). Prefixes: ``damage_``, ``friction_``
(Newton), ``uzawa_``, ``pd_``.
"""
from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from damage_dolfinx.core.tags import GAMMA_C, GAMMA_D, GAMMA_N

from damage_dolfinx import compat
from damage_dolfinx.numerics.boundary import bilateral_plane_faces, clamped
from damage_dolfinx.forms.constitutive import eps, von_mises
from damage_dolfinx.numerics.contact_output import near_contact
from damage_dolfinx.forms.kelvin_voigt import kelvin_voigt_stress, velocity_step_forms
from damage_dolfinx.numerics.friction import FrictionProblem, iteration_counters, solver_from_parameters
from damage_dolfinx.models.base import DAMAGE_A, Model, SubStep
from damage_dolfinx.numerics.friction import FRICTION_DEFAULTS, FRICTION_RULES
from damage_dolfinx.core.parameters import ModelParameters


class KelvinVoigtTresca(Model):
    """Problem VP^{hk} of Section 2.2."""

    id = "2.2"
    title = "quasistatic Kelvin-Voigt body, bilateral contact with Tresca friction"
    contact_roles = ("tresca",)
    stability_limit = "explicit elastic term: k <= 2/m_visc"
    checkpoint_fields = ("u", "zeta", "v")
    old_state = (("u", "u_old"), ("zeta", "zeta_old"))
    update = ("u", "u_old", "v")  # (2.68) u_n = u_{n-1} + k v_n

    #: the rules of the model's own data (name -> (test, what it must be))
    rules = {
        **FRICTION_RULES,
    }

    @classmethod
    def defaults(cls) -> ModelParameters:
        return ModelParameters(E=5000.0, nu=0.3, **DAMAGE_A,
                               extra={"m_visc": 100.0, "g_fric": 5.0, **FRICTION_DEFAULTS})

    @classmethod
    def k_max(cls, params) -> float:
        """The velocity step A eps(v_n) = -zeta Phi_L(B eps(u_{n-1})) + ..., A = B/m_visc with
        the same boundary conditions, gives u_n = (1 - k m_visc zeta) u_{n-1} mode by mode:
        stable iff k m_visc zeta <= 2, so k_max = 2/m_visc (zeta <= 1)."""
        return 2.0 / float(params.extra["m_visc"])

    def __init__(self, data):
        super().__init__(data)
        p, msh, x = self.params, self.mesh, data.params.extra
        V, Z = compat.vector_p1(msh), compat.scalar_p1(msh)
        self.u, self.u_old = fem.Function(V, name="u"), fem.Function(V, name="u_old")
        self.v = fem.Function(V, name="v")
        self.zeta, self.zeta_old = fem.Function(Z, name="zeta"), fem.Function(Z, name="zeta_old")
        self.k = data.time.k

        # (1) damage obstacle step, explicit source
        self.damage = self.obstacle_damage_step()

        # (2) velocity second-kind VI with bilateral contact and Tresca friction
        tags = data.geometry.facet_tags
        ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
        f_B, f_N = self.loads()
        w = ufl.TestFunction(V)
        a, l = velocity_step_forms(ufl.TrialFunction(V), w, self.u_old, self.zeta_old, p.E, p.nu,
                                   x["m_visc"], p.L_trunc, f_B, f_N, ds(GAMMA_N))
        bcs = [clamped(V, tags, GAMMA_D)] + bilateral_plane_faces(V, tags, GAMMA_C)
        g_builder = data.builders.get("friction_bound")
        g = g_builder(ufl.SpatialCoordinate(msh)) if g_builder else fem.Constant(msh, x["g_fric"])
        self.friction_problem = FrictionProblem(self.v, a, l, bcs, g, ds(GAMMA_C), self.context)
        self.friction = solver_from_parameters(self.friction_problem, x, tags, GAMMA_D,
                                               data.id)
        self._probe_setup(data.builders.get("probe"), ufl.action(a, self.v) - l)

        Q = compat.scalar_dg0(msh)
        self.von_mises = fem.Function(Q, name="von_mises")
        sigma = kelvin_voigt_stress(self.v, self.u, self.zeta, p.E, p.nu, x["m_visc"], p.L_trunc)
        self._vm_expr = compat.expression(von_mises(sigma), Q)
        self.output_fields = [self.u, self.v, self.zeta, self.von_mises]
        self.timings = {"damage": 0.0, "friction": 0.0}

    def scheme(self) -> tuple:
        return (SubStep("damage", "snes-vi", "damage_", self.damage.solve,       # (1)
                        its=("damage_its",)),
                SubStep("friction", "newton", "friction_", self.friction.solve,  # (2.67)
                        its=("snes_its",)))

    def update_output(self):
        compat.interpolate(self.von_mises, self._vm_expr)

    @classmethod
    def declared_columns(cls, problem, dim: int) -> list:
        """The probe's columns when ``builders["probe"]`` names a point (_probe_setup)."""
        return [] if problem.builders.get("probe") is None else ["probe_u1", "probe_sigma_tau"]

    # -- a point on Gamma_C whose horizontal displacement and tangential stress are recorded
    def _probe_setup(self, point, residual_form):
        self.extra_history_columns = self.declared_columns(self.data, self.mesh.topology.dim)
        if point is None:
            return
        nodes = self.friction.nodes  # contact nodes, weights and tangents of the solver
        X = self.v.function_space.tabulate_dof_coordinates()[nodes.dofs, :len(point)]
        dist = np.linalg.norm(X - np.asarray(point), axis=1)
        local_best = float(dist.min()) if dist.size else np.inf
        best = self.comm.allreduce(local_best, op=MPI.MIN)
        candidate = self.comm.rank if local_best <= best else self.comm.size
        owner = self.comm.allreduce(candidate, op=MPI.MIN)
        index = int(np.argmin(dist)) if self.comm.rank == owner else None
        # only its rows on Gamma_C are read: assembled over the cells that touch Gamma_C
        residual = compat.form(near_contact(residual_form, self.v.function_space,
                                            self.data.geometry.facet_tags))
        self._probe = (nodes, index, residual, compat.create_vector(residual))

    def scalars(self) -> dict:
        out = super().scalars()
        if not hasattr(self, "_probe"):
            return out
        nodes, i, residual, r = self._probe  # R(w) = a(v, w) - l(w) = -sum_i m_i Phi_i w_tau,i
        with r.localForm() as rl:
            rl.set(0.0)
        compat.assemble_vector(r, residual)
        r.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        values = np.zeros(2)
        if i is not None:
            d = nodes.dim
            values[0] = self.u.x.array.reshape(-1, d)[nodes.dofs[i], 0]
            R = r.getArray().reshape(-1, d)[nodes.dofs[i]]
            if d == 2:
                values[1] = float(R @ nodes.tau[i]) / nodes.m[i]  # sigma_tau = -Phi_i = R.tau / m
            else:  # 3-D: the size of the tangential stress vector
                values[1] = float(np.linalg.norm(nodes.tau[i] @ R)) / nodes.m[i]
        values = self.comm.allreduce(values, op=MPI.SUM)
        out["probe_u1"], out["probe_sigma_tau"] = float(values[0]), float(values[1])
        return out

    def iteration_totals(self) -> dict:
        return {"damage_snes": self.damage.iterations, "friction": self.friction.iterations,
                "friction_solver": self.friction.name, **iteration_counters(self.friction)}
