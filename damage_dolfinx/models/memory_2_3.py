"""Section 2.3: quasistatic viscoelastic body with long memory, frictionless normal compliance
and damage (PDE form, variant A), scheme (2.136)-(2.137).

    u_0:  (B eps(u_0), eps(w)) + (p_nu(u_0.nu), w.nu)_{Gamma_C} = L_0(w)      (Remark 2.3, no memory)
    n>=1: (zeta_n - zeta_{n-1}, xi) + k kappa (grad zeta_n, grad xi) = k (phi_A(eps(u_{n-1}), zeta_{n-1}), xi)
          M_n = sum_{j=1..n} k G(t_n - t_{j-1}, eps(u_{j-1}), zeta_{j-1})                    (2.136)
          (B eps(u_n) + M_n, eps(w)) + (p_nu(u_n.nu - gap), w.nu)_{Gamma_C} = L_n(w)         (2.137)

p_nu(r) = c_nu r_+ (semismooth Newton, SNES prefix ``mech_``: the residual assembled once per
step at u_{n-1}, then F(u_{n-1}) + K (u - u_{n-1}) + the change of the Gamma_C term, K the
constant (B eps(du), eps(w)); the Jacobian K + the Gamma_C term factorised again only when the
latter changes); damage PDE step prefix ``damage_`` (matrix factorised once). The dimension comes from the mesh: on a 3-D mesh
B is 3-D Hooke, M_n a 3x3 tensor, Gamma_C any plane or curved face; from
``scalable.DIRECT_MAX_DOFS_3D`` unknowns on, Newton's linear systems are solved by CG +
BoomerAMG (``mech_contact_amg``; the AMG set-up lagged like the factorisation in 2-D) and
the damage PDE by CG + BoomerAMG. The memory term is updated in O(1) per step for constant
and exponential kernels (memory.py).
"""
from __future__ import annotations

from functools import partial


import numpy as np
import ufl
from dolfinx import fem

from damage_dolfinx.core.tags import GAMMA_C, GAMMA_D, GAMMA_N

from damage_dolfinx import compat
from damage_dolfinx.numerics import scalable
from damage_dolfinx.numerics.boundary import clamped
from damage_dolfinx.forms.constitutive import B_coefficients, eps, von_mises
from damage_dolfinx.numerics.damage import DamageStep
from damage_dolfinx.forms.viscoelastic_memory import displacement_residual, memory_stress, total_stress
from damage_dolfinx.numerics.memory import CellwiseIntegrand, MemoryKernel, MemoryTerm
from damage_dolfinx.numerics.split_residual import SplitResidual, affine_cell_split
from damage_dolfinx.core.parameters import InputError
from damage_dolfinx.numerics.solvers import NEWTON, NonlinearSolver, lagged_direct
from damage_dolfinx.models.base import DAMAGE_A, Model, SubStep
from damage_dolfinx.models.contact import NormalComplianceScalars
from damage_dolfinx.core.parameters import ModelParameters
from damage_dolfinx.numerics import bookkeeping


#: Krylov iterations above which the lagged Jacobian factorisation is rebuilt (with a Krylov
#: -mech_ksp_type; the default applies the factorisation once, mech_direct)
MECH_REFACTOR_ITS = 10


def mech_contact_amg():
    """Newton defaults of the 3-D displacement step at size: CG + hypre BoomerAMG (where PETSc
    has hypre; None otherwise: the lagged direct solve). GAMG, the elasticity default of
    scalable.py, fails here: with the near-rigid foundation (c_nu = 1e10 against E = 100) its
    Chebyshev/Jacobi smoother gave an indefinite preconditioner once the contact term was active
    (2.3-ex1-3d, n = 10 and 20), with SOR smoothing a failed level solve at n = 20; BoomerAMG
    converges in a few CG iterations per Newton step there (benchmarks/README.md, "Why the
    defaults")."""
    return {**NEWTON, **scalable.damage_amg()} if scalable.has_hypre() else None


def mech_direct(comm) -> dict:
    """Newton defaults of the displacement step below the AMG size: the lagged direct solve's
    factorisation (PETSc's Cholesky serially, MUMPS in parallel) applied once (``preonly``).
    The factorisation is rebuilt whenever the Jacobian changes (a new contact set), so it is
    the Jacobian's own and Newton is exact; CG on it (the lagged default, ``-mech_ksp_type
    cg``) converged in one iteration at the cost of a second triangular solve per Newton
    step (2.3-ex1, ex3: the same factorisations, 165 against 116 solves on ex3)."""
    return {**NEWTON, **lagged_direct(comm), "ksp_type": "preonly"}


class ViscoelasticMemoryContact(NormalComplianceScalars, Model):
    """Problem VP^{hk} of Section 2.3."""

    id = "2.3"
    title = "quasistatic viscoelastic body with long memory, normal compliance"
    contact_roles = ("normal_compliance",)
    history_columns = ("penetration_rms", "stress_L2")
    old_state = (("zeta", "zeta_old"),)  # u_{n-1} stays in u until (2.137) replaces it

    #: the rules of the model's own data (name -> (test, what it must be))
    rules = {
        "memory_kernel": (lambda v: v in ("constant", "exponential"),
                          "must be 'constant' or 'exponential'"),
        "memory_rate": (lambda v: v >= 0, "(decay rate of the exponential kernel) must be >= 0"),
        "memory_mode": (lambda v: v in ("auto", "running", "recursive", "sum"),
                        "must be one of auto, running, recursive, sum"),
    }

    @classmethod
    def defaults(cls) -> ModelParameters:
        return ModelParameters(E=1e4, nu=0.3, **dict(DAMAGE_A, lam_D=1e-2, lam_u=10.0),
                               extra={"c_nu": 1e10, "gap": 0.0, "memory_kernel": "constant",
                                      "memory_amplitude": 1.0, "memory_rate": 1.0,
                                      "memory_mode": "auto"})

    def __init__(self, data, mech_prefix="mech_", damage_prefix="damage_"):
        super().__init__(data)
        p, msh, x = self.params, self.mesh, data.params.extra
        V, Z = compat.vector_p1(msh), compat.scalar_p1(msh)
        self.u = fem.Function(V, name="u")
        self.zeta = fem.Function(Z, name="zeta")
        self.zeta_old = fem.Function(Z, name="zeta_old")
        k = data.time.k
        self.c_nu, self.gap = float(x["c_nu"]), float(x.get("gap", 0.0))

        # (1.5): damage PDE step with phi_A at step n-1
        phi_old = self.damage_source(eps(self.u), self.zeta_old)
        self.damage = DamageStep(self.zeta, self.zeta_old, phi_old, fem.Constant(msh, k),
                                 fem.Constant(msh, float(p.kappa)), self.context,
                                 obstacle=False, zeta_star=p.zeta_star, prefix=damage_prefix,
                                 linear_defaults=scalable.damage_config(Z),
                                 irreversible=data.irreversible)

        # (2.136): memory, g evaluated at (u_{n-1}, zeta_{n-1}) before u and zeta move on
        kernel = MemoryKernel(x["memory_kernel"], float(x.get("memory_amplitude", 1.0)),
                              float(x.get("memory_rate", 1.0)))
        self.memory = MemoryTerm(msh, kernel, k, x.get("memory_mode", "auto"))
        # g = zeta Phi_L(B eps(u)): the stress factor at one point per cell (P1 u), times zeta
        self._g_expr = CellwiseIntegrand(memory_stress(self.u, p.E, p.nu, p.L_trunc), self.zeta,
                                         self.memory.space)

        # (2.137): nonlinear displacement step
        tags = data.geometry.facet_tags
        ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
        self.n_facet = ufl.FacetNormal(msh)
        f_B, f_N = self.loads()
        F = displacement_residual(self.u, ufl.TestFunction(V), self.memory.M, p.E, p.nu,
                                  self.c_nu, self.gap, self.n_facet, f_B, f_N, ds(GAMMA_N),
                                  ds(GAMMA_C))
        bc = clamped(V, tags, GAMMA_D)
        self._residual = None  # the split residual of the lagged direct path
        if scalable.iterative(V) and mech_contact_amg():  # 3-D at size: CG + BoomerAMG
            self.mech = NonlinearSolver(F, self.u, [bc], mech_prefix, self.context,
                                        defaults=mech_contact_amg(),
                                        refactor_after_its=scalable.MECH_AMG_REBUILD_ITS)
            J, P = self.mech.snes.snes.getJacobian()[:2]
            modes = scalable.rigid_body_modes(V)
            for A in (J, P):
                A.setNearNullSpace(modes)
        else:  # 2-D and small 3-D: a factorisation kept while the Jacobian is unchanged;
            # the Jacobian is the constant K = (B eps(du), eps(w)) plus the Gamma_C term,
            # which alone is assembled per Newton step (a large part of the step), and only
            # when its values change (the key); the residual is assembled
            # once per step, then updated by K (x - x_0) and the Gamma_C term
            # (split_residual.py)
            split = affine_cell_split(F, self.u)  # (K, r, dr/du): F = F_cell + r
            self._residual = SplitResidual(self.u, [bc], split)
            self.mech = NonlinearSolver(F, self.u, [bc], mech_prefix, self.context,
                                        defaults=mech_direct(msh.comm),
                                        refactor_after_its=MECH_REFACTOR_ITS,
                                        jacobian_split=(split[0], split[2]),
                                        residual=self._residual,
                                        jacobian_key=self._residual.jacobian_key)
            self.mech.jacobian_change_tol = 0.0  # refactorised at any change: exact Newton
            self._residual.attach(self.mech.form_residual)

        Q = compat.scalar_dg0(msh)
        self.von_mises = fem.Function(Q, name="von_mises")
        self._vm_expr = compat.expression(
            von_mises(total_stress(self.u, self.memory.M, p.E, p.nu)), Q)
        self._contact_setup(ds(GAMMA_C))
        # ||sigma_n||^2 per cell in NumPy (P1 u, DG1 M on affine simplices), else assembled
        self._stress_norm = None
        if bookkeeping.AffineStressNorm.applies(self.u, self.memory.M):
            a, b = B_coefficients(msh.topology.dim, p.E, p.nu)
            self._stress_norm = bookkeeping.AffineStressNorm(self.u, self.memory.M, a, b)
        sigma = total_stress(self.u, self.memory.M, p.E, p.nu)
        self._stress_sq = compat.form(ufl.inner(sigma, sigma) * ufl.dx)
        self.output_fields = [self.u, self.zeta, self.von_mises]
        self.timings = {"damage": 0.0, "memory": 0.0, "mech": 0.0}
        self._prefixes = damage_prefix, mech_prefix

    def checkpoint_state(self) -> dict:
        """u, zeta and the memory M_n (running/recursive modes keep no other history)."""
        if self.memory.mode == "sum":
            raise InputError("memory mode 'sum' stores the whole history: no checkpoints")
        return {**super().checkpoint_state(), "memory": self.memory.M}

    def start(self) -> dict:
        its = self._timed("mech", self._mech_solve)
        return {"mech_its": its}

    def _mech_solve(self) -> int:
        """(2.137) by Newton from u_{n-1}, whose residual is assembled first."""
        if self._residual is not None:
            self._residual.begin()
        return self.mech.solve()

    def scheme(self) -> tuple:
        """The memory M_n first, from g(u_{n-1}, zeta_{n-1}) (2.136), then the damage step (1.5)
        and the displacement (2.137) by semismooth Newton."""
        damage_prefix, mech_prefix = self._prefixes
        return (SubStep("memory", "update", "",                                    # (2.136)
                        partial(self.memory.update, self._g_expr)),
                SubStep("damage", "linear", damage_prefix, self.damage.solve,      # (1.5)
                        its=("damage_its",)),
                SubStep("mech", "semismooth", mech_prefix, self._mech_solve,       # (2.137)
                        its=("snes_its",)))

    def update_output(self):
        compat.interpolate(self.von_mises, self._vm_expr)

    def track(self):
        """Between history rows (--history-every): nothing to do, scalars() keeps no running
        values (the run's state check still runs every step)."""

    def scalars(self) -> dict:
        """Base scalars, the RMS penetration (u.nu - gap)_+ over Gamma_C and ||sigma_n||_Q
        (per cell without an assembly where bookkeeping.AffineStressNorm applies: exact)."""
        if self._stress_norm is not None:  # summed in the base scalars' reduction
            out, (stress_sq,) = self.base_scalars([self._stress_norm.local()])
        else:
            out = super().scalars()
            stress_sq = compat.assemble_scalar(self._stress_sq, self.comm)
        out["stress_L2"] = float(np.sqrt(max(stress_sq, 0.0)))
        out["penetration_rms"] = self.penetration_rms()
        return out

    def iteration_totals(self) -> dict:
        return {"damage_ksp": self.damage.iterations, "snes": self.mech.iterations,
                "mech_ksp": self.mech.linear_iterations,
                "mech_factorizations": self.mech.factorizations}
