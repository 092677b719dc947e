"""Section 3.1: dynamic Kelvin-Voigt body, frictionless normal compliance, damage by the obstacle
inclusion (variant A), scheme (3.48)-(3.51):

    (1) zeta_n in K^h:  (zeta_n - zeta_{n-1}, xi - zeta_n) + k kappa (grad zeta_n, grad(xi - zeta_n))
                        >= k (phi_A(eps(u_{n-1}), zeta_{n-1}), xi - zeta_n)      (3.49), SNES vinewtonrsls
    (2) v_n in V^h:     (rho (v_n - v_{n-1})/k, w) + (A eps(v_n), eps(w))
                        = L_n(w) - (zeta_{n-1} Phi_L(B eps(u_{n-1})), eps(w))
                          - int_{Gamma_C} c_nu (u_{n-1}.nu - gap)_+ w.nu ds        (3.48), linear
    (3) u_n = u_{n-1} + k v_n                                                    (3.51)

V = {v = 0 on Gamma_D}; u_0 = v_0 = 0, zeta_0 from the example. The matrix of (2) does not change
for a fixed k: it is factorised once (prefix ``mech_``), each step assembles a right-hand
side. Serially it is stored by 2x2 (3x3) blocks and factorised by PETSc's own LU with nested
dissection (solvers.serial_block_lu: a cheaper solve and factorisation than PETSc's scalar
Cholesky, itself faster than MUMPS's solves; benchmarks/README.md, "Why the defaults"), by
MUMPS LU in parallel. The right-hand side's inertia term is M_rho/k v_{n-1}, the
mass matrix assembled once (LinearSolver's rhs_product). The dimension comes
from the mesh: on 3-D meshes with at least
``VELOCITY_DIRECT_MAX_DOFS_3D`` unknowns the velocity system is solved by CG + GAMG with the
rigid-body near-nullspace (AMG set up once, CG started from v_{n-1}) instead.
Damage prefix ``damage_``. Parameters in ``extra``: rho, m_visc, c_nu, gap,
``damage_active`` (False: zeta frozen at zeta_0 and step (1) skipped, Example 3's undamaged run)
``stability_check`` (warn | error | off: k against the limit of the explicit elastic and
contact forces, stability.py; docs/models.md, "Stability of the explicit terms") and
``error_norm`` (velocity: convergence errors in the norm of Cor. 3.1, ||v||_L2 + ||zeta||_L2
(docs/models.md, section 3.1); displacement: ||eps(u)||_L2 + ||zeta||_L2).
"""
from __future__ import annotations

from functools import partial

import time

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from damage_dolfinx.core.tags import GAMMA_C, GAMMA_D, GAMMA_N

from damage_dolfinx import compat
from damage_dolfinx.numerics import bookkeeping
from damage_dolfinx.numerics import scalable
from damage_dolfinx.numerics.boundary import clamped
from damage_dolfinx.forms.constitutive import eps, von_mises
from damage_dolfinx.forms.dynamic_kelvin_voigt import inertia_form, total_stress, velocity_step_forms
from damage_dolfinx.numerics.solvers import DIRECT, LinearSolver, serial_block_lu
from damage_dolfinx.models.base import DAMAGE_A, Model, SubStep
from damage_dolfinx.models.contact import NormalComplianceScalars
from damage_dolfinx.core.parameters import ModelParameters


#: 3-D velocity systems with at least this many unknowns: CG + GAMG instead of one factorisation.
#: scalable.py's rule, measured for 100-step runs (benchmarks/reference_output/contact_3d/
#: crossover.md): above it the factorisation's cost overtakes its cheaper solves (long runs on
#: mid-size meshes: -mech_ksp_type preonly -mech_pc_type lu)
VELOCITY_DIRECT_MAX_DOFS_3D = scalable.DIRECT_MAX_DOFS_3D


class DynamicKelvinVoigt(NormalComplianceScalars, Model):
    """Problem VP^{hk} of Section 3.1."""

    id = "3.1"
    title = "dynamic Kelvin-Voigt body, normal compliance"
    contact_roles = ("normal_compliance",)
    dynamic = True
    checks_time_step = True  # k against its eigenvalue estimate (stability_check)
    stability_limit = "explicit elastic and contact forces (eigenvalue estimate)"
    checkpoint_fields = ("u", "zeta", "v")
    history_columns = ("v_L2", "u_max", "penetration_rms")
    old_state = (("u", "u_old"), ("v", "v_old"), ("zeta", "zeta_old"))
    update = ("u", "u_old", "v")  # (3.51) u_n = u_{n-1} + k v_n

    #: the rules of the model's own data (name -> (test, what it must be))
    rules = {
        "error_norm": (lambda v: v in ("velocity", "displacement", "velocity_only"),
                       "(convergence error of Section 3.1) must be velocity, displacement or "
                       "velocity_only"),
    }

    @classmethod
    def defaults(cls) -> ModelParameters:
        return ModelParameters(E=1e4, nu=0.3, **dict(DAMAGE_A, kappa=1.0, q_star=1.0),
                               extra={"rho": 1.0, "m_visc": 10.0, "c_nu": 1e4, "gap": 0.0,
                                      "damage_active": True, "stability_check": "error",
                                      "error_norm": "velocity"})

    def __init__(self, data, mech_prefix="mech_", damage_prefix="damage_"):
        super().__init__(data)
        p, msh, x = self.params, self.mesh, data.params.extra
        V, Z = compat.vector_p1(msh), compat.scalar_p1(msh)
        self.u, self.u_old = fem.Function(V, name="u"), fem.Function(V, name="u_old")
        self.v, self.v_old = fem.Function(V, name="v"), fem.Function(V, name="v_old")
        self.zeta, self.zeta_old = fem.Function(Z, name="zeta"), fem.Function(Z, name="zeta_old")
        self.k = data.time.k
        self.rho, self.m_visc = float(x["rho"]), float(x["m_visc"])
        self.c_nu, self.gap = float(x["c_nu"]), float(x.get("gap", 0.0))
        self.damage_active = bool(x.get("damage_active", True))
        # ||v||_H + ||zeta||_Y (Cor. 3.1; the thesis does not state its norm);
        # displacement: ||u||_V + ||zeta||_Y;
        # velocity_only: ||v||_H (the reading that reproduces Table 3.1's magnitude)
        self.error_components = {
            "velocity": [("v", self.v, "L2"), ("zeta", self.zeta, "L2")],
            "displacement": [("u", self.u, "V"), ("zeta", self.zeta, "L2")],
            "velocity_only": [("v", self.v, "L2")]}[x.get("error_norm", "velocity")]

        # (3.49): damage obstacle step, explicit source
        self.damage = None
        if self.damage_active:
            self.damage = self.obstacle_damage_step(damage_prefix)

        # (3.48): velocity, a constant matrix
        tags = data.geometry.facet_tags
        ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
        self.n_facet = ufl.FacetNormal(msh)
        self.has_contact = self.comm.allreduce(int(np.sum(tags.values == GAMMA_C)), op=MPI.SUM) > 0
        f_B, f_N = self.loads()
        const = lambda value: fem.Constant(msh, float(value))  # noqa: E731
        a, l = velocity_step_forms(ufl.TrialFunction(V), ufl.TestFunction(V), self.v_old,
                                   self.u_old, self.zeta_old, const(self.rho), const(self.k), p.E,
                                   p.nu, self.m_visc, p.L_trunc, const(self.c_nu),
                                   const(self.gap), self.n_facet, f_B, f_N, ds(GAMMA_N),
                                   ds(GAMMA_C) if self.has_contact else None,
                                   inertia_rhs=False)
        self.bcs = [clamped(V, tags, GAMMA_D)]
        # (rho v_{n-1}/k, w)_H as M_rho/k v_{n-1}: the mass matrix made once, one sparse product
        # a step instead of a second quadrature loop and v_{n-1}'s coefficients in the assembly
        inertia = (inertia_form(ufl.TrialFunction(V), ufl.TestFunction(V), const(self.rho),
                                const(self.k)), self.v_old)
        self.mech = LinearSolver(a, l, self.bcs, mech_prefix, self.context, constant_matrix=True,
                                 rhs_product=inertia, block_matrix=True,
                                 defaults=scalable.constant_config(
                                     V, serial_block_lu(msh.comm, DIRECT), mech_prefix))
        scalable.prepare_mech(self.mech, V)  # near-nullspace; with AMG: warm start
        self.stability = self._stability_check(V, x, ds(GAMMA_C))

        # output: von Mises of the total stress and of the strain, DG0 (docs/models.md, "Output
        # conventions")
        Q = compat.scalar_dg0(msh)
        self.von_mises = fem.Function(Q, name="von_mises")
        self.von_mises_strain = fem.Function(Q, name="von_mises_strain")
        sigma = total_stress(self.v, self.u, self.zeta, p.E, p.nu, self.m_visc, p.L_trunc)
        self._vm_expr = compat.expression(von_mises(sigma), Q)
        self._vm_strain_expr = compat.expression(von_mises(eps(self.u)), Q)
        self.figure_fields = {"von_mises_strain": (self.von_mises_strain,
                                                   "von Mises norm of the strain [-]")}
        self._contact_setup(ds(GAMMA_C))
        self.output_fields = [self.u, self.v, self.zeta, self.von_mises, self.von_mises_strain]
        self.timings = {"damage": 0.0, "velocity": 0.0, "stability": self.stability.get("time_s", 0.0)}
        self._prefixes = damage_prefix, mech_prefix

    # -- the scheme
    def scheme(self) -> tuple:
        """The damage step (3.49) (none when ``damage_active`` is off: 0 iterations), then the
        velocity (3.48), a linear solve with a constant matrix."""
        damage_prefix, mech_prefix = self._prefixes
        return (SubStep("damage", "snes-vi", damage_prefix,                        # (3.49)
                        self.damage.solve if self.damage else None, its=("damage_its",)),
                SubStep("velocity", "linear", mech_prefix, partial(self.mech.solve, self.v),
                        its=("mech_its",)))                                          # (3.48)

    def update_output(self):
        compat.interpolate(self.von_mises, self._vm_expr)
        compat.interpolate(self.von_mises_strain, self._vm_strain_expr)

    # -- stability of the explicit elastic and contact forces (docs/models.md, section 3.1)
    def _stability_check(self, V, x, dsC) -> dict:
        """k_max of the scheme (undamaged, Gamma_C fully in contact: conservative), compared with
        k according to ``stability_check``; {} when off."""
        action = x.get("stability_check", "warn")
        if action == "off":
            return {}
        from damage_dolfinx.numerics.stability import checked, estimate_stability
        start = time.perf_counter()
        out = estimate_stability(V, self.params.E, self.params.nu, self.rho, self.m_visc,
                                 c_nu=self.c_nu if self.has_contact else 0.0, dsC=dsC,
                                 bcs=self.bcs, normal=self.n_facet, k=self.k)
        where = f"{self.data.id}: explicit elastic and contact forces, eigenvalue estimate"
        checked(out, self.k, where, action)
        out["time_s"] = time.perf_counter() - start
        return out

    def summary_extra(self) -> dict:
        if not self.stability:
            return {}
        return {"k_max": self.stability["k_max"], "k_over_k_max": self.stability["k_over_k_max"],
                "k_max_lower_bound": self.stability.get("k_max_lower_bound"),
                "stability": self.stability}

    # -- scalars: ||v||_L2, max |u| at the nodes, RMS penetration on Gamma_C
    def u_max(self) -> float:
        """max over the nodes of |u_n| (the L-shape comparison of Example 3)."""
        owned = self.u.function_space.dofmap.index_map.size_local
        d = self.mesh.topology.dim
        return bookkeeping.max_node_norm(self.u.x.array[:owned * d], d, self.comm)

    def track(self):
        """Between history rows (--history-every): nothing to do, scalars() keeps no running
        values (the run's state check still runs every step)."""

    def scalars(self) -> dict:
        """The base scalars (||u||_L2, ||eps(u)||_L2, zeta min/max/mean), ||v||_L2 and max |u|
        in one pass with one reduction, from the matrices assembled once (the base class's
        u^T M u, u^T K_eps u, m . zeta). Two matrix products a step instead of three: M v_n
        gives ||v_n||_L2 and, by (3.51) u_n = u_{n-1} + k v_n, M u_n = M u_{n-1} + k M v_n
        (M u_{n-1} kept from the previous step's scalars; computed directly after a restart,
        at t = 0 or after a step without scalars). Equal to the direct products to round-off
        (relative 1e-16 per step)."""
        norms = self.field_norms()
        u_sq, eps_sq, v_sq = norms.carried_parts(self.v, self.n, self.k)  # (3.51)
        values = norms.u
        zeta_integral, lo, hi = norms.zeta_parts()
        d = self.mesh.topology.dim
        nodes = values.reshape(-1, d)
        u_max_sq = float(np.einsum("ij,ij->i", nodes, nodes).max()) if nodes.size else 0.0
        (u_sq, eps_sq, zeta_integral, v_sq), (neg_min, zeta_max, u_max_sq) = \
            bookkeeping.sums_and_maxima(self.comm, [u_sq, eps_sq, zeta_integral, v_sq],
                                        [-lo, hi, u_max_sq])
        return {"u_L2": float(np.sqrt(max(u_sq, 0.0))), "eps_u_L2": float(np.sqrt(max(eps_sq, 0.0))),
                "zeta_min": -neg_min, "zeta_max": zeta_max,
                "zeta_mean": float(zeta_integral / norms.area), "v_L2": float(np.sqrt(abs(v_sq))),
                "u_max": float(np.sqrt(u_max_sq)), "penetration_rms": self.penetration_rms()}

    def iteration_totals(self) -> dict:
        return {"damage_snes": self.damage.iterations if self.damage else 0,
                "mech_ksp": self.mech.iterations, "mech_factorizations": self.mech.factorizations}
