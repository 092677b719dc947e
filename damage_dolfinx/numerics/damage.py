"""Damage source functions (1.3), (1.4) and the discrete damage step (docs/models.md, "The
damage step").

The step is either the linear PDE solve (1.5) (Sections 2.1, 2.3) with a matrix factorised once,
or the obstacle problem over K^h = {zeta_star <= zeta <= 1} solved by PETSc SNES
``vinewtonrsls`` with nodal bounds (Sections 2.2, 2.4, 3.x). Both use the consistent mass matrix.
"""
from __future__ import annotations

import math

import ufl
from dolfinx import fem
from petsc4py import PETSc

from damage_dolfinx import compat
from damage_dolfinx.forms.constitutive import Psi_q, eta_star, split_norms_sq
from damage_dolfinx.forms.damage import damage_step_forms
from damage_dolfinx.numerics.held_data import AssembledFrom
from damage_dolfinx.numerics.obstacle import CHOLESKY_MAX_DOFS, ObstacleFastPath, fast_path_options
from damage_dolfinx.numerics.solvers import (DIRECT, ConvergenceError, LinearSolver, SNESSolver, SolveContext,
                      serial_cholesky)


def phi_A(e, z, p):
    """Variant A (1.3): lam_D (1 - eta_*(z))/eta_*(z) - 0.5 lam_u Psi_q(e) - lam_w."""
    ez = eta_star(z, p.zeta_star)
    return p.lam_D * (1.0 - ez) / ez - 0.5 * p.lam_u * Psi_q(e, p.q_star) - p.lam_w


def phi_B(e, z, p):
    """Variant B (1.4): lam_D (1 - z)/eta_*(z) - 0.5 lam_u^- Psi_q(e^-) - 0.5 lam_u^+ Psi_q(e^+) - lam_w.

    Psi_q of the split parts is min(|e^+-|^2, q_star), from the closed-form 2-D eigenvalues.
    """
    pos_sq, neg_sq = split_norms_sq(e)
    return (p.lam_D * (1.0 - z) / eta_star(z, p.zeta_star)
            - 0.5 * p.lam_u_minus * ufl.min_value(neg_sq, p.q_star)
            - 0.5 * p.lam_u_plus * ufl.min_value(pos_sq, p.q_star)
            - p.lam_w)


def source(e, z, p):
    """The damage source phi(eps, zeta) of the variant selected in ``p`` (A or B)."""
    return phi_A(e, z, p) if p.variant == "A" else phi_B(e, z, p)


def fast_path_counts(stepper) -> dict:
    """The fast-path counts of a stepper's damage obstacle step (summary.json "iterations")."""
    step = getattr(stepper, "damage", None)
    return step.counts() if hasattr(step, "counts") else {}


#: SNES defaults of the obstacle step; override with -damage_snes_* options.
#: The reduced systems (inactive set) are mass-dominated, M + k kappa K: CG + Jacobi to rtol 1e-12
#: solves them in a few iterations without a factorisation per Newton step, several times
#: faster than MUMPS LU with the same fields (benchmarks/README.md, "Why the defaults").
OBSTACLE_DEFAULTS = {"snes_type": "vinewtonrsls", "snes_rtol": 1e-10, "snes_atol": 1e-12,
                     "snes_stol": 0.0, "snes_max_it": 50, "snes_linesearch_type": "basic",
                     "ksp_type": "cg", "pc_type": "jacobi", "ksp_rtol": 1e-12, "ksp_atol": 1e-50,
                     "ksp_max_it": 1000}


#: absolute SNES tolerance of the obstacle step relative to ||l|| (the CG accuracy), and the
#: relative step below which the active-set iteration has converged
OBSTACLE_ATOL_REL = 1e-9
OBSTACLE_STEP_RTOL = 1e-10


class DamageStep:
    """zeta_n from b(zeta_n, xi) = l(xi) (PDE) or the VI b(zeta_n, xi - zeta_n) >= l(xi - zeta_n).

    ``zeta`` receives the new damage; ``zeta_old`` and ``phi_old`` (a UFL expression of the
    step n-1 state) enter the right-hand side. The matrix b is constant for a fixed k: it is
    assembled (and, for the PDE form, factorised) once, and again before a solve when a
    Function or Constant in it (a ``kappa`` or ``k`` of the model's own) has changed.
    """

    def __init__(self, zeta: fem.Function, zeta_old: fem.Function, phi_old, k, kappa,
                 context: SolveContext, obstacle: bool, zeta_star: float = 0.01,
                 prefix: str = "damage_", linear_defaults=None, irreversible: bool = False):
        V = zeta.function_space
        a, L = damage_step_forms(ufl.TrialFunction(V), ufl.TestFunction(V), zeta_old, phi_old,
                                 k, kappa)
        self.zeta, self.zeta_old, self.obstacle = zeta, zeta_old, obstacle or irreversible
        #: (new, old) pairs read from the previous step: old must be the copy of new made at
        #: the start of the step (a model's old_state; models/contracts.py checks it)
        self.previous_state = ((zeta, zeta_old),)
        # irreversibility: zeta_n <= zeta_{n-1} as the upper bound of the obstacle step; the PDE
        # step (1.5) then becomes the obstacle problem over {zeta <= zeta_{n-1}} (no lower bound)
        self.irreversible = irreversible
        if not self.obstacle:
            # linear_defaults: KSP options of the PDE form (None: direct, the matrix
            # M + k kappa K being SPD by PETSc's Cholesky serially; 3-D: scalable.py)
            self.linear = LinearSolver(a, L, [], prefix, context, constant_matrix=True,
                                       defaults=linear_defaults or
                                       serial_cholesky(V.mesh.comm, DIRECT))
            return
        enabled, solver = fast_path_options(prefix)  # a bad option is refused before any work
        self.a, self.L = compat.form(a), compat.form(L)
        self.A = compat.create_matrix(self.a)
        compat.assemble_matrix(self.A, self.a, [])
        self.A.assemble()
        self._a_data = AssembledFrom(a, V.mesh.comm)  # assembled again when it changes
        self.b = compat.create_vector(self.L)
        self.lower, self.upper = self.b.duplicate(), self.b.duplicate()
        self.lower.set(zeta_star if obstacle else PETSc.NINFINITY)
        self.upper.set(1.0)
        self.snes = SNESSolver(V.mesh.comm, prefix, context, self._residual, self._jacobian,
                               self.b.duplicate(), self.A, OBSTACLE_DEFAULTS,
                               bounds=(self.lower, self.upper))
        self._atol = self.snes.snes.getTolerances()[1]
        self.atol_rel = OBSTACLE_ATOL_REL  # a problem may lower it (3.3 wrench: 0)
        self._f0 = None
        self.snes.snes.setConvergenceTest(self._converged)
        self.lu_retries = 0
        # The SNES's first iteration with cached linear algebra (obstacle.py);
        # -<prefix>vi_fast 0 restores the SNES alone, bit for bit
        self._new_fast_path = lambda: ObstacleFastPath(
            self.A, zeta_star, 1.0, self.snes.snes.getKSP(), solver,
            CHOLESKY_MAX_DOFS[V.mesh.topology.dim])
        self.fast = self._new_fast_path() \
            if enabled and obstacle and not irreversible else None  # scalar bounds only
        self._atol_set, self._rtol, self._vecs = None, None, None
        self._parallel = V.mesh.comm.size > 1

    def _converged(self, snes, it, norms):
        """PETSc's default tests plus a step test for the VI: when many nodes sit within
        round-off of a bound (3.3, lam_D = 0), the active set settles a few nodes per iteration
        while the steps are already tiny (seen: 4e-9 for ||z|| = 257 at n = 256): stop when
        ||dz|| <= OBSTACLE_STEP_RTOL ||z||."""
        xnorm, ynorm, fnorm = norms
        rtol, atol, _, max_it = snes.getTolerances()
        reason = PETSc.SNES.ConvergedReason
        if it == 0:
            self._f0 = fnorm
        if fnorm != fnorm:
            return reason.DIVERGED_FNORM_NAN
        if fnorm <= atol:
            return reason.CONVERGED_FNORM_ABS
        if it > 0 and fnorm <= rtol * self._f0:
            return reason.CONVERGED_FNORM_RELATIVE
        if it > 0 and ynorm <= OBSTACLE_STEP_RTOL * max(xnorm, 1.0):
            return reason.CONVERGED_SNORM_RELATIVE
        if it >= max_it:
            return reason.DIVERGED_MAX_IT
        return reason.ITERATING

    def _residual(self, x, f):
        """F(z) = B z - l: the damage step is affine, so no re-assembly inside Newton."""
        self.A.mult(x, f)
        f.axpy(-1.0, self.b)

    def _jacobian(self, x, J):
        """The Jacobian is the constant matrix B, assembled once."""

    def solve(self) -> int:
        """Compute zeta_n; returns iterations (KSP for the PDE form, Newton for the VI)."""
        if not self.obstacle:
            return self.linear.solve(self.zeta)
        if self.irreversible:  # the upper bound is zeta_{n-1}
            compat.petsc_vec(self.zeta_old).copy(self.upper)
        if self._a_data.changed():  # (collective) a datum of b changed: b and its solvers anew
            self.A.zeroEntries()
            compat.assemble_matrix(self.A, self.a, [])
            self.A.assemble()
            if self.fast is not None:
                self.fast = self._new_fast_path()
        with self.b.localForm() as bl:
            bl.set(0.0)
        compat.assemble_vector(self.b, self.L)
        self.b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        # a source that is not finite (an overflow of phi) would be clipped to the bounds by the
        # obstacle solvers and give a finite, wrong zeta: the run fails instead, on every model
        norm = self.b.norm()  # collective: every rank decides alike
        if not math.isfinite(norm):
            raise ConvergenceError("the damage source phi(eps, zeta) is not finite (NaN or Inf): "
                                   "the model's data overflow (e.g. a lam_u of 1e300)")
        # the reduced systems are solved to CG accuracy relative to ||l||: an absolute
        # tolerance below that is unreachable on large domains (3.3 Ex. 1, (0,6)^2)
        atol = max(self._atol, self.atol_rel * norm) if self.atol_rel else self._atol
        if atol != self._atol_set:  # PETSc is told only when it changes
            self.snes.snes.setTolerances(atol=atol)
            self._atol_set = atol
            self._rtol = self.snes.snes.getTolerances()[0]
        if self.fast is not None:
            if self._vecs is None:  # the PETSc views of zeta_old, zeta (stable)
                self._vecs = (compat.petsc_vec(self.zeta_old), compat.petsc_vec(self.zeta))
            if self.fast.step(self._vecs[0], self.b, self._vecs[1], atol, self._rtol):
                if self._parallel:
                    self.zeta.x.scatter_forward()
                return 0  # no SNES iteration
        self.zeta.x.array[:] = self.zeta_old.x.array
        try:
            its = self.snes.solve(compat.petsc_vec(self.zeta))
        except ConvergenceError:  # active-set cycling with inexact CG: once more with LU
            self.lu_retries += 1
            self.zeta.x.array[:] = self.zeta_old.x.array
            its = self._solve_with_lu()
        self.zeta.x.scatter_forward()
        return its

    def _solve_with_lu(self) -> int:
        ksp = self.snes.snes.getKSP()
        ksp_type, pc_type = ksp.getType(), ksp.getPC().getType()
        ksp.setType("preonly")
        ksp.getPC().setType("lu")
        try:
            return self.snes.solve(compat.petsc_vec(self.zeta))
        finally:
            ksp.setType(ksp_type)
            ksp.getPC().setType(pc_type)

    def counts(self) -> dict:
        """Fast-path hits, SNES fallbacks and reduced-solver set-ups (obstacle form only)."""
        return self.fast.counts() if getattr(self, "fast", None) is not None else {}

    @property
    def iterations(self) -> int:
        return self.linear.iterations if not self.obstacle else self.snes.iterations
