"""Direct solves with J = A + diag(K) for a constant SPD matrix A and a diagonal K that lives on
a few rows C and changes from solve to solve.

The friction Jacobians of friction/ have this form: A is the constant matrix of the velocity
(or increment) step and K sits on the tangential dofs of the contact nodes (nodal quadrature,
axis-parallel tangents). K changes whenever the stick set or the multipliers change, which in a
stick-slip phase is every Newton or active-set iteration; a new Cholesky factorisation of J each
time costs many triangular solves (benchmarks/README.md, "Why the defaults").

:class:`DiagonalUpdateSolver` therefore splits the unknowns into C and the rest I and uses the
exact static condensation

    [A_II  A_IC     ] [x_I]   [b_I]      (S + D) x_C = b_C - A_CI A_II^{-1} b_I,
    [A_CI  A_CC + D ] [x_C] = [b_C],     x_I = A_II^{-1} (b_I - A_IC x_C),

with A_II factorised once per run and the Schur complement S = A_CC - A_CI A_II^{-1} A_IC
(|C| x |C|, dense, replicated on every rank) computed once: a new K costs one dense Cholesky of
S + D (|C| is about the number of contact nodes, ~130 at 33k dofs), a solve two triangular
solves with A_II. When the same K is used by REFACTOR_AFTER consecutive solves (a steady
stick set: few Newton iterations per step), J itself is factorised once and used while K
stays (one triangular solve per solve, as before). Both paths are exact direct solves; they
differ by round-off. The condensation is built lazily, at the first solve with a K other than
the factorised one.

3-D friction has 2x2 blocks per contact node instead of a diagonal: the condensation
would carry over (S + D with a block-diagonal D), but it is kept 2-D only; 3-D uses
:class:`BlockUpdateSolver` (J = A + blocks assembled, factorised or AMG-preconditioned by its KSP).
"""
from __future__ import annotations

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from damage_dolfinx.numerics.solvers import set_default_options, spd_direct

#: consecutive solves with one K after which J = A + diag(K) itself is factorised
REFACTOR_AFTER = 4
#: S + D counts as singular (as a zero pivot of PETSc's Cholesky) below this relative pivot
ZERO_PIVOT = 1e-12


class DiagonalUpdateSolver:
    """x = (A + diag(K))^{-1} b for K supported on ``rows`` (local indices of owned rows).

    ``solve(K, b, x)`` returns False (x unspecified) when A + diag(K) is singular, like a
    failed Cholesky factorisation. ``K`` is the local array of the diagonal on ``rows``."""

    def __init__(self, A: PETSc.Mat, rows: np.ndarray, prefix: str):
        self.A, self.prefix = A, prefix
        self.comm = A.getComm().tompi4py()
        start, end = A.getOwnershipRange()
        self.rows = np.asarray(rows, dtype=np.int64)
        rest = np.setdiff1d(np.arange(end - start), self.rows)
        self._is_C = PETSc.IS().createGeneral((start + self.rows).astype(PETSc.IntType),
                                              comm=self.comm)
        self._is_I = PETSc.IS().createGeneral((start + rest).astype(PETSc.IntType), comm=self.comm)
        self.size_C = self.comm.allreduce(self.rows.size)
        # the full factorisation of J (used while K stays)
        self.J = A.duplicate(copy=True)
        self._d = self.J.createVecLeft()
        self.full = self._ksp(prefix, self.J)
        self.K_full = None
        self._K_last, self._repeats = None, 0
        self._schur = None  # built at first need
        # -<prefix>condense 0: factorise J at every new K instead (the earlier behaviour)
        self.condense = PETSc.Options().getBool(prefix + "condense", True)
        self.full_factorizations = self.condensed_factorizations = 0
        self.full_solves = self.condensed_solves = 0
        # the dense Cholesky of S + D: imported here, at set-up, not inside a step's
        # timing, and only by the runs that build this solver
        import scipy.linalg
        self._linalg = scipy.linalg

    def _ksp(self, prefix, M):
        set_default_options(prefix, spd_direct(self.comm))
        ksp = PETSc.KSP().create(self.comm)
        ksp.setOptionsPrefix(prefix)
        ksp.setOperators(M)
        ksp.setFromOptions()
        return ksp

    # -- the condensation (once per run)
    def _build_schur(self):
        A = self.A
        self.A_II = A.createSubMatrix(self._is_I, self._is_I)
        self.A_IC = A.createSubMatrix(self._is_I, self._is_C)
        self.A_CC = A.createSubMatrix(self._is_C, self._is_C)
        self.inner = self._ksp(self.prefix + "inner_", self.A_II)
        self.inner.setUp()
        t_I, z_I = self.A_II.createVecs()
        e_C, c_C = self.A_CC.createVecs()
        s_C = c_C.duplicate()
        to_all, s_all = PETSc.Scatter.toAll(c_C)
        S = self._schur_columns(t_I, z_I, e_C, c_C, s_C, to_all, s_all) if self.comm.size == 1 \
            else self._schur_block()
        self.S = 0.5 * (S + S.T)  # symmetric up to round-off
        # where each rank's C rows sit in the global C numbering
        offsets = np.cumsum([0] + self.comm.allgather(self.rows.size))
        self._c_lo, self._c_hi = offsets[self.comm.rank], offsets[self.comm.rank + 1]
        template = A.createVecLeft()
        self._work = dict(b_I=t_I, y_I=z_I, s_I=t_I.duplicate(), b_C=c_C, s_C=s_C,
                          x_C=c_C.duplicate(), to_all=to_all, s_all=s_all,
                          to_I=PETSc.Scatter().create(template, self._is_I, t_I, None),
                          to_C=PETSc.Scatter().create(template, self._is_C, c_C, None))
        self._cho, self._K_cho = None, None
        self._schur = True

    def _schur_columns(self, t_I, z_I, e_C, c_C, s_C, to_all, s_all):
        """S column by column (serial: as fast as MatMatSolve with PETSc's Cholesky)."""
        r = self.size_C
        S = np.empty((r, r))
        lo, hi = e_C.getOwnershipRange()
        for j in range(r):  # column j of S = A_CC e_j - A_CI A_II^{-1} A_IC e_j
            e_C.set(0.0)
            if lo <= j < hi:
                e_C.setValue(j, 1.0)
            e_C.assemble()
            self.A_IC.mult(e_C, t_I)
            self.inner.solve(t_I, z_I)
            if self.inner.getConvergedReason() < 0:
                raise RuntimeError(f"{self.prefix}inner: factorisation of A_II failed")
            self.A_IC.multTranspose(z_I, s_C)
            self.A_CC.mult(e_C, c_C)
            c_C.axpy(-1.0, s_C)
            to_all.scatter(c_C, s_all, PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
            S[:, j] = s_all.getArray(readonly=True)
        return S

    def _schur_block(self):
        """S by one MatMatSolve with all columns of A_IC (MUMPS on several ranks: faster
        than column by column), gathered on every rank."""
        B = self.A_IC.convert("dense")
        X = B.duplicate()
        self.inner.getPC().getFactorMatrix().matSolve(B, X)
        S = self.A_CC.convert("dense")
        S.axpy(-1.0, self.A_IC.transposeMatMult(X))
        return np.vstack(self.comm.allgather(S.getDenseArray().copy()))

    def _condensed(self, K, b, x) -> bool:
        if self._schur is None:
            self._build_schur()
        w = self._work
        K_all = np.concatenate(self.comm.allgather(K))
        if self._K_cho is None or not np.array_equal(K_all, self._K_cho):
            M = self.S + np.diag(K_all)
            try:
                L = self._linalg.cholesky(M, lower=True)
            except np.linalg.LinAlgError:
                return False
            if np.min(np.diag(L)) ** 2 <= ZERO_PIVOT * np.max(np.abs(np.diag(M))):
                return False
            self._cho, self._K_cho = (L, True), K_all
            self.condensed_factorizations += 1
        b_I, y_I, s_I, b_C, s_C, x_C = (w[key] for key in ("b_I", "y_I", "s_I", "b_C", "s_C", "x_C"))
        fwd, rev, ins = PETSc.ScatterMode.FORWARD, PETSc.ScatterMode.REVERSE, PETSc.InsertMode.INSERT
        w["to_I"].scatter(b, b_I, ins, fwd)
        w["to_C"].scatter(b, b_C, ins, fwd)
        self.inner.solve(b_I, y_I)                      # y = A_II^{-1} b_I
        self.A_IC.multTranspose(y_I, s_C)               # b_C - A_CI y
        b_C.axpy(-1.0, s_C)
        w["to_all"].scatter(b_C, w["s_all"], ins, fwd)
        x_C_all = self._linalg.cho_solve(self._cho, w["s_all"].getArray(readonly=True))
        x_C.setArray(x_C_all[self._c_lo:self._c_hi])
        self.A_IC.mult(x_C, s_I)                        # x_I = A_II^{-1} (b_I - A_IC x_C)
        b_I.axpy(-1.0, s_I)
        self.inner.solve(b_I, y_I)
        w["to_I"].scatter(y_I, x, ins, rev)
        w["to_C"].scatter(x_C, x, ins, rev)
        self.condensed_solves += 1
        return True

    # -- the full factorisation (while K stays)
    def _factorise_full(self, K):
        self._d.set(0.0)
        self._d.getArray()[self.rows] = K
        self.A.copy(self.J, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        self.J.setDiagonal(self._d, addv=PETSc.InsertMode.ADD_VALUES)
        self.full.setOperators(self.J)  # factorised at the next solve
        self.full_factorizations += 1
        self.K_full = K.copy()

    def _same(self, K, other) -> bool:
        return self.comm.allreduce(bool(other is not None and np.array_equal(K, other)),
                                   op=MPI.LAND)

    def solve(self, K: np.ndarray, b: PETSc.Vec, x: PETSc.Vec) -> bool:
        """x = (A + diag(K on rows))^{-1} b; False if that matrix is singular."""
        K = np.asarray(K, dtype=float)
        self._repeats = self._repeats + 1 if self._same(K, self._K_last) else 1
        self._K_last = K.copy()
        if not self._same(K, self.K_full) and (not self.condense or self.K_full is None
                                                or self._repeats >= REFACTOR_AFTER):
            self._factorise_full(K)
        if self._same(K, self.K_full):
            self.full.solve(b, x)
            self.full_solves += 1
            return self.full.getConvergedReason() > 0
        return self._condensed(K, b, x)


class DiagonalUpdatePC:
    """A petsc4py Python PC applying (A + diag(K))^{-1} by a DiagonalUpdateSolver, for the K that
    its owner sets with ``set_K`` (e.g. from a SNES Jacobian callback), and the matching
    operator A + diag(K) as a Python shell matrix (``operator``: what the SNES multiplies by,
    e.g. its local-minimum check after a failed line search). A singular matrix gives a NaN
    direction, which the SNES reports as a failure (like a zero pivot)."""

    def __init__(self, solver: DiagonalUpdateSolver):
        self.solver, self.K = solver, None
        A = solver.A
        self._d = A.createVecLeft()
        self.operator = PETSc.Mat().createPython(A.getSizes(), context=self, comm=A.getComm())
        self.operator.setUp()

    def set_K(self, K):
        self.K = np.asarray(K, dtype=float)
        self._d.set(0.0)
        self._d.getArray()[self.solver.rows] = self.K
        self.operator.assemble()  # a new operator state

    def attach(self, ksp: PETSc.KSP):
        ksp.setType("preonly")
        pc = ksp.getPC()
        pc.setType("python")
        pc.setPythonContext(self)

    def apply(self, pc, b, x):
        if not self.solver.solve(self.K, b, x):
            x.set(np.nan)

    # the shell matrix A + diag(K) (symmetric)
    def mult(self, mat, x, y):
        self.solver.A.mult(x, y)
        work = self._d.duplicate()
        work.pointwiseMult(self._d, x)
        y.axpy(1.0, work)
        work.destroy()

    def multTranspose(self, mat, x, y):
        self.mult(mat, x, y)


class BlockUpdateSolver:
    """x = (A + sum_i E_i K_i E_i^T)^{-1} b for 2x2 blocks K_i on the two tangential dofs of each
    contact node (3-D friction; ``rows`` (nodes, 2) local indices of owned rows).

    The static condensation of :class:`DiagonalUpdateSolver` is 2-D only: here J is assembled
    (a copy of A plus the blocks, in A's sparsity: a node's dofs are coupled there) and
    factorised by the KSP of ``prefix`` whenever K changes. Rows that carry a Dirichlet condition
    (``free`` False) keep A's identity row and column. ``solve(K, b, x)`` returns False when the
    solve fails (a singular J). KSP ``defaults``: Cholesky unless given (e.g. lu_direct for a
    non-symmetric K, or CG + GAMG with the ``near_nullspace`` of scalable.py).

    With ``lag_its`` the KSP is a Krylov method (GMRES unless the defaults say otherwise)
    preconditioned by the factorisation of an earlier J (the matrix P), refreshed when a solve
    needed more than ``lag_its`` iterations; a failed solve is repeated once with P = J."""

    def __init__(self, A: PETSc.Mat, rows: np.ndarray, free: np.ndarray, prefix: str,
                 defaults=None, near_nullspace=None, lag_its=None):
        self.A, self.prefix = A, prefix
        self.comm = A.getComm().tompi4py()
        start, _ = A.getOwnershipRange()
        self.global_rows = (start + np.asarray(rows, dtype=np.int64)).astype(PETSc.IntType)
        self.mask = (free[:, :, None] & free[:, None, :]).astype(float)
        self.J = A.duplicate(copy=True)
        defaults = dict(defaults or spd_direct(self.comm))
        if lag_its is not None:
            defaults.update({"ksp_type": "gmres", "ksp_rtol": 1e-12, "ksp_atol": 1e-50,
                             "ksp_max_it": 200, "ksp_norm_type": "unpreconditioned"})
        set_default_options(prefix, defaults)
        if near_nullspace is not None:
            self.J.setNearNullSpace(near_nullspace)
        self.lag_its = lag_its
        self.P = self.J.duplicate(copy=True) if lag_its is not None else self.J
        self.ksp = PETSc.KSP().create(self.comm)
        self.ksp.setOptionsPrefix(prefix)
        self.ksp.setOperators(self.J, self.P)
        self.ksp.setFromOptions()
        self._K, self._stale, self._fresh = None, True, False
        self.factorizations = self.solves = 0

    def set_K(self, K: np.ndarray):
        """J = A + blocks K (nodes, 2, 2), re-assembled only when K changed (on some rank)."""
        K = np.asarray(K, dtype=float) * self.mask
        same = self._K is not None and np.array_equal(K, self._K)
        if self.comm.allreduce(bool(same), op=MPI.LAND):
            return
        self.A.copy(self.J, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        for rows, block in zip(self.global_rows, K):
            self.J.setValues(rows, rows, block, addv=PETSc.InsertMode.ADD_VALUES)
        self.J.assemble()
        self._K = K
        self.factorizations += 1  # of J (with lag_its: assemblies; P re-factorised on _refresh)

    def solve(self, K, b, x) -> bool:
        self.set_K(K)
        if self.P is not self.J and self._stale:
            self._refresh()
        self.ksp.solve(b, x)
        self.solves += 1
        if self.P is self.J:
            return self.ksp.getConvergedReason() > 0
        if self.ksp.getConvergedReason() < 0 and not self._fresh:  # stale P: once with P = J
            self._refresh()
            self.ksp.solve(b, x)
        self._stale = self.ksp.getIterationNumber() > self.lag_its
        self._fresh = False
        return self.ksp.getConvergedReason() > 0

    def _refresh(self):
        """P = J (re-factorised at the next solve)."""
        self.J.copy(self.P, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        self.P.assemble()
        self._fresh = True


def lu_direct(comm) -> dict:
    """Direct LU solve (a non-symmetric J): PETSc's in serial, MUMPS in parallel."""
    package = "petsc" if comm.size == 1 else "mumps"
    return {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": package}
