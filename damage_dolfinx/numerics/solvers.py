"""Thin petsc4py wrappers: linear (KSP) and nonlinear/bound-constrained (SNES) solvers.

Every solver has a PETSc options prefix (``damage_``, ``mech_`` ...): package defaults are put in
the options database only where the user has not set the option, so ``-mech_ksp_type cg
-mech_pc_type gamg`` on the command line wins. Every solve checks the converged reason and
raises :class:`ConvergenceError` naming the example, the step, the time and the residual.
"""
from __future__ import annotations

import time
from collections import defaultdict
from dataclasses import dataclass

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from damage_dolfinx import compat
from damage_dolfinx.numerics.callbacks import form_callbacks, relative_change
from damage_dolfinx.numerics.held_data import AssembledFrom


from damage_dolfinx.core.errors import ConvergenceError  # noqa: F401


@dataclass
class SolveContext:
    """Where a solve happens; shared by the solvers of one run and updated by the time loop."""
    example: str = "?"
    step: int = 0
    t: float = 0.0

    def where(self) -> str:
        """'in example ID, step N, t = T' for error messages."""
        return f"in example {self.example}, step {self.step}, t = {self.t:.6g}"


def _reason_name(enum, reason: int) -> str:
    for name in dir(enum):
        if not name.startswith("_") and getattr(enum, name) == reason:
            return name
    return str(reason)


#: options this module put into the PETSc database (full name -> value), as opposed to options
#: the user gave (command line, -prefix_option value), which always win
_CODE_DEFAULTS = {}


def set_default_options(prefix: str, defaults: dict):
    """Put ``defaults`` under ``prefix`` in the PETSc options database; options the user set
    are kept. Code defaults of an earlier solver with the same prefix (several problems in one
    process, e.g. the tests) are replaced, and those the new defaults do not name are removed,
    so that one solver's defaults never leak into another's (e.g. a nonzero initial guess into
    a preonly LU solve)."""
    opts = PETSc.Options()
    for name in [n for n in _CODE_DEFAULTS if n.startswith(prefix)]:
        if name[len(prefix):] not in defaults:
            if _ours(opts, name):
                opts.delValue(name)
            del _CODE_DEFAULTS[name]
    for key, value in defaults.items():
        name = prefix + key
        if _ours(opts, name) or not opts.hasName(name):
            opts[name] = value
            _CODE_DEFAULTS[name] = value


def _ours(opts, name) -> bool:
    """Whether the option ``name`` holds the value this module put there (a value the user set
    since, e.g. between two runs of a script, is the user's and stays)."""
    return name in _CODE_DEFAULTS and opts.hasName(name) and \
        opts.getString(name, "").lower() == str(_CODE_DEFAULTS[name]).lower()


def replace_default_option(name: str, value):
    """Change one option this module put into the database (a user's option stays)."""
    opts = PETSc.Options()
    if _ours(opts, name) or not opts.hasName(name):
        opts[name] = value
        _CODE_DEFAULTS[name] = value


#: direct solve, factorisation reused while the matrix is unchanged
DIRECT = {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}


def spd_direct(comm) -> dict:
    """Direct solve of a symmetric positive (semi)definite matrix: Cholesky, by PETSc's own
    factorisation in serial (its triangular solves are faster than MUMPS's at these sizes;
    benchmarks/README.md, "Why the defaults") and by MUMPS in parallel."""
    package = "petsc" if comm.size == 1 else "mumps"
    return {"ksp_type": "preonly", "pc_type": "cholesky", "pc_factor_mat_solver_type": package}


#: CG preconditioned by an exact factorisation of an earlier matrix (lagged), for SPD operators
#: that change slowly from step to step (damaged elasticity): the factorisation is redone only
#: when CG needs more than ``refactor_after_its`` iterations.
LAGGED_DIRECT = {"ksp_type": "cg", "ksp_rtol": 1e-12, "ksp_atol": 1e-50, "ksp_max_it": 200,
                 "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}


def serial_cholesky(comm, options: dict) -> dict:
    """``options`` (a factorisation by MUMPS LU) with PETSc's own Cholesky serially, for SPD
    matrices: its triangular solves are faster than MUMPS's (spd_direct), which shortens the
    steps of the convergence references. Unchanged in parallel (the measurement:
    benchmarks/README.md, "Why the defaults")."""
    if comm.size > 1:
        return dict(options)
    return {**options, "pc_type": "cholesky", "pc_factor_mat_solver_type": "petsc"}


def serial_block_lu(comm, options: dict) -> dict:
    """``options`` (a factorisation by MUMPS LU) with PETSc's own LU (nested dissection)
    serially, for a LinearSolver with ``block_matrix=True`` on a vector space: the matrix is
    then stored by bs x bs blocks (BAIJ) and the triangular solves work on blocks. Unchanged in
    parallel. On 3.1-ex1's velocity matrix both its solve and its factorisation are cheaper than
    the scalar Cholesky of serial_cholesky (benchmarks/README.md, "Why the defaults")."""
    if comm.size > 1:
        return dict(options)
    return {**options, "pc_type": "lu", "pc_factor_mat_solver_type": "petsc"}


def _petsc_lu(prefix: str) -> bool:
    """The options database asks for PETSc's own LU under ``prefix`` (a block matrix fits)."""
    opts = PETSc.Options()
    return opts.getString(prefix + "pc_type", "") == "lu" and \
        opts.getString(prefix + "pc_factor_mat_solver_type", "petsc") == "petsc"


def lagged_direct(comm) -> dict:
    """LAGGED_DIRECT, with PETSc's Cholesky serially (the lagged matrices are SPD)."""
    return serial_cholesky(comm, LAGGED_DIRECT)


class LinearSolver:
    """Solve a(u, w) = L(w) with Dirichlet conditions by a PETSc KSP.

    With ``constant_matrix=True`` the matrix is assembled and factorised once, and again only
    when a Function or Constant of ``a`` has changed since (:mod:`held_data`: a datum of the
    state is never held at its value when the solver was built). Otherwise it is re-assembled
    in place each solve (same sparsity); with ``refactor_after_its`` set and a
    Krylov KSP (default options LAGGED_DIRECT) the preconditioner (an exact factorisation of an
    earlier matrix) is kept until the iteration count exceeds that number, and rebuilt at once
    if the lagged solve fails.

    ``rhs_product=(r, f)`` (r a bilinear form, f a Function) adds R f to the right-hand side,
    R the matrix of r assembled once (no boundary conditions; again when a Function or Constant
    of r has changed): a term r(f, w) of the linear
    form taken out of L, e.g. the inertia (rho v_{n-1}/k, w) as M v_{n-1}/k (one sparse product
    instead of a quadrature loop and its coefficient packing at every assembly). When every
    Dirichlet value is zero (checked at each assembly) the lifting is skipped: it would
    subtract A 0.

    ``block_matrix=True`` (a vector space): serially, when the options (defaults and the
    user's) ask for PETSc's own LU, the matrix is stored by blocks of the space's block size
    (see serial_block_lu); any other solver gets the usual AIJ matrix.
    """

    def __init__(self, a, L, bcs, prefix: str, context: SolveContext, constant_matrix=False,
                 defaults=None, refactor_after_its=None, rhs_product=None, block_matrix=False):
        self.a, self.L, self.bcs = compat.form(a), compat.form(L), list(bcs)
        self._product = None
        if rhs_product is not None:
            r, f = rhs_product
            self._r = compat.form(r)
            R = compat.create_matrix(self._r)
            self._product = (R, compat.petsc_vec(f))
            self._r_data = AssembledFrom(r, R.getComm().tompi4py())
            self._assemble_product()
        self.prefix, self.context, self.constant_matrix = prefix, context, constant_matrix
        set_default_options(prefix, DIRECT if defaults is None else defaults)
        self.b = compat.create_vector(self.L)
        blocked = block_matrix and self.b.getComm().getSize() == 1 and _petsc_lu(prefix)
        self.A = compat.create_matrix(self.a, "baij" if blocked else None)
        self._assembled = False
        #: what a constant matrix was assembled from (assembled again when it changes)
        self._a_data = AssembledFrom(a, self.A.getComm().tompi4py()) if constant_matrix else None
        self.ksp = PETSc.KSP().create(self.A.getComm())
        self.ksp.setOptionsPrefix(prefix)
        self.ksp.setOperators(self.A)
        self.ksp.setFromOptions()
        self.lagged = bool(refactor_after_its) and not constant_matrix and \
            self.ksp.getType() != "preonly"
        self.refactor_after_its = refactor_after_its
        self._fresh_pc_needed = True
        self.iterations = 0
        self.solves = 0
        self.factorizations = 0
        self.timings = defaultdict(float)  # seconds: assemble_matrix, assemble_rhs, solve

    def assemble_matrix(self):
        start = time.perf_counter()
        self.A.zeroEntries()
        compat.assemble_matrix(self.A, self.a, self.bcs)
        self.A.assemble()
        self._assembled = True
        self.timings["assemble_matrix"] += time.perf_counter() - start

    def _assemble_product(self):
        R = self._product[0]
        R.zeroEntries()
        compat.assemble_matrix(R, self._r, [])
        R.assemble()

    def assemble_rhs(self):
        start = time.perf_counter()
        if self._product is not None and self._r_data.changed():
            self._assemble_product()
        with self.b.localForm() as bl:
            bl.set(0.0)
        compat.assemble_vector(self.b, self.L)
        if not compat.dirichlet_values_zero(self.bcs):
            compat.apply_lifting(self.b, self.a, self.bcs)
        self.b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        if self._product is not None:
            R, f = self._product
            R.multAdd(f, self.b, self.b)  # owned entries; the Dirichlet rows are set next
        compat.set_bc(self.b, self.bcs)
        self.timings["assemble_rhs"] += time.perf_counter() - start

    def solve(self, u):
        """Solve into the Function ``u``; returns the KSP iteration count."""
        changed = self._a_data.changed() if self.constant_matrix else True  # (collective)
        if changed or not self._assembled:
            self.assemble_matrix()
        self.assemble_rhs()
        x = compat.petsc_vec(u)
        reason = self._ksp_solve(x)
        if reason < 0 and self.lagged:  # the lagged factorisation was not good enough: redo it
            self._fresh_pc_needed = True
            reason = self._ksp_solve(x)
        if reason < 0:
            r = self.b.duplicate()
            self.A.mult(x, r)
            r.aypx(-1.0, self.b)
            raise ConvergenceError(
                f"{self.prefix}ksp did not converge ({_reason_name(PETSc.KSP.ConvergedReason, reason)}) "
                f"{self.context.where()}, residual {r.norm():.3e}")
        u.x.scatter_forward()
        its = self.ksp.getIterationNumber()
        self.iterations += its
        self.solves += 1
        if self.lagged and its > self.refactor_after_its:
            self._fresh_pc_needed = True
        return its

    def factorise_now(self):
        """Assemble the matrix as the form reads it now and factorise it as the lagged
        preconditioner of the next solves (a restart rebuilds the interrupted run's one)."""
        self.assemble_matrix()
        self.ksp.getPC().setReusePreconditioner(False)
        self.ksp.setUp()
        self._fresh_pc_needed = False
        self.factorizations += 1

    def _ksp_solve(self, x) -> int:
        fresh = self._fresh_pc_needed or not self.lagged
        if self.lagged:
            self.ksp.getPC().setReusePreconditioner(not fresh)
            self._fresh_pc_needed = False
        if fresh and (self.solves == 0 or not self.constant_matrix):
            self.factorizations += 1
        start = time.perf_counter()
        self.ksp.solve(self.b, x)
        self.timings["solve"] += time.perf_counter() - start
        return self.ksp.getConvergedReason()


class SNESSolver:
    """A PETSc SNES on callbacks F(x, b) and J(x, A) with an options prefix and optional bounds.

    The iterate is a private copy of the unknown's vector (line searches must not overwrite the
    state the callbacks read, dolfinx PR #3507); bounds ``(lb, ub)`` are passed by reference, so
    in-place changes take effect at the next solve.
    """

    def __init__(self, comm, prefix: str, context: SolveContext, residual, jacobian, b, A,
                 defaults: dict, bounds=None, P=None):
        self.prefix, self.context = prefix, context
        self._residual_cb, self._jacobian_cb = residual, jacobian
        set_default_options(prefix, defaults)
        self.snes = PETSc.SNES().create(comm)
        self.snes.setOptionsPrefix(prefix)
        self.snes.setFunction(lambda snes, x, f: residual(x, f), b)
        if P is None:
            self.snes.setJacobian(lambda snes, x, J, P_: jacobian(x, J), A)
        else:  # separate preconditioning matrix, updated by the callback when it chooses
            self.snes.setJacobian(lambda snes, x, J, P_: jacobian(x, J, P_), A, P)
        if bounds is not None:
            self.snes.setVariableBounds(*bounds)
        self.snes.setFromOptions()
        self.iterations = 0
        self.linear_iterations = 0
        self.solves = 0

    def solve(self, x_state: PETSc.Vec) -> int:
        """Solve starting from ``x_state`` and write the solution back; returns Newton iterations."""
        x = x_state.copy()
        self.snes.solve(None, x)
        reason = self.snes.getConvergedReason()
        if reason <= 0:
            raise ConvergenceError(
                f"{self.prefix}snes did not converge ({_reason_name(PETSc.SNES.ConvergedReason, reason)}) "
                f"{self.context.where()}, residual {self.snes.getFunctionNorm():.3e} after {self.snes.getIterationNumber()} iterations")
        x.copy(x_state)
        x_state.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        x.destroy()
        its = self.snes.getIterationNumber()
        self.iterations += its
        self.linear_iterations += self.snes.getLinearSolveIterations()
        self.solves += 1
        return its


#: Newton defaults (semismooth Newton on max(., 0) terms); override with -<prefix>snes_* options
NEWTON = {"snes_type": "newtonls", "snes_linesearch_type": "basic", "snes_rtol": 1e-10,
          "snes_atol": 1e-10, "snes_stol": 1e-14, "snes_max_it": 50,
          "snes_divergence_tolerance": compat.PETSC_UNLIMITED, **DIRECT}


class NonlinearSolver:
    """Newton (PETSc SNES) for F(u; w) = 0 with Dirichlet conditions, Jacobian from UFL.

    With ``refactor_after_its`` (and a Krylov KSP, default options NEWTON with lagged_direct:
    symmetric Jacobians whose active set rarely changes, e.g. normal compliance) the
    factorisation of an earlier Jacobian preconditions the current one and is rebuilt only when
    the previous linear solve needed more than that many iterations or the Jacobian changed by
    more than ``jacobian_change_tol`` (Frobenius, relative; 1e-10, i.e. any change): Newton
    stays exact (the linear systems are solved to rtol 1e-12, or directly with ``preonly`` when
    the factorised matrix equals the Jacobian), the factorisations become rare. The lag works
    through a separate preconditioning matrix P: PETSc re-factorises only when P changes, and P
    is refreshed (re-assembled as the current Jacobian) only when needed. With
    ``jacobian_key(x)`` (a local array on which the Jacobian alone depends, e.g. the stick set
    and eps), even the assembly is skipped while the key is unchanged. ``residual(x, b)``
    replaces the assembly of F (same contract as the callback of :func:`callbacks.form_callbacks`);
    ``jacobian_split`` (:func:`callbacks.constant_cell_jacobian`) assembles only the varying part of J.
    """

    def __init__(self, F, u, bcs, prefix: str, context: SolveContext, defaults=None,
                 refactor_after_its=None, J=None, jacobian_key=None, residual=None,
                 jacobian_split=None):
        import ufl
        self.u = u
        self.jacobian_key, self._last_key = jacobian_key, None
        if J is None:
            J = ufl.derivative(F, u, ufl.TrialFunction(u.function_space))
        self.form_residual, jacobian, b, A = form_callbacks(F, J, u, bcs, jacobian_split)
        # a residual callback (x, b) that replaces the assembly of F, e.g. an algebraic one;
        # it must also copy x into u, from which the Jacobian is assembled
        residual = residual or self.form_residual
        if defaults is None:
            defaults = {**NEWTON, **lagged_direct(u.function_space.mesh.comm)} \
                if refactor_after_its else NEWTON
        self.refactor_after_its = refactor_after_its
        self.jacobian_change_tol = 1e-10  # any change, e.g. of a contact or stick set
        self.factorizations = 0
        self._force_fresh = False
        P = compat.create_matrix(compat.form(J)) if refactor_after_its else None
        self.snes = SNESSolver(u.function_space.mesh.comm, prefix, context, residual,
                               self._lagged(jacobian) if refactor_after_its else jacobian,
                               b, A, defaults, P=P)
        self.ksp = self.snes.snes.getKSP()
        self.timings = defaultdict(float)

    def _lagged(self, jacobian):
        def lagged_jacobian(x, A, P):
            if self.jacobian_key is not None and self._same_key(x) and not self._force_fresh:
                return  # the Jacobian depends only on the key (e.g. a stick set): unchanged
            jacobian(x, A)
            krylov = self.ksp.getType() != "preonly"
            fresh = (self.factorizations == 0 or self._force_fresh
                     or (krylov and self.ksp.getIterationNumber() > self.refactor_after_its)
                     or relative_change(A, P) > self.jacobian_change_tol)
            if fresh:
                jacobian(x, P)
                self.factorizations += 1
                self._force_fresh = False
        return lagged_jacobian

    def solve(self) -> int:
        """Solve from the current value of u (warm start); returns Newton iterations."""
        start = time.perf_counter()
        x = compat.petsc_vec(self.u)
        guess = x.copy()  # the callbacks write trial iterates into u: keep the start
        try:
            its = self.snes.solve(x)
        except ConvergenceError:
            self._restore(guess)
            if not self.refactor_after_its:
                raise
            self._force_fresh = True  # the lagged preconditioner may be to blame: retry once
            try:
                its = self.snes.solve(x)
            except ConvergenceError:
                self._restore(guess)
                raise
        self.u.x.scatter_forward()
        self.timings["solve"] += time.perf_counter() - start
        return its

    def _same_key(self, x) -> bool:
        """True when ``jacobian_key(x)`` equals the key of the last assembled Jacobian on every
        rank (the key is then stored)."""
        key = self.jacobian_key(x)
        same = self._last_key is not None and np.array_equal(key, self._last_key)
        self._last_key = key
        return self.u.function_space.mesh.comm.allreduce(bool(same), op=MPI.LAND)

    def _restore(self, guess):
        guess.copy(compat.petsc_vec(self.u))
        self.u.x.scatter_forward()

    @property
    def iterations(self):
        return self.snes.iterations

    @property
    def linear_iterations(self):
        return self.snes.linear_iterations
