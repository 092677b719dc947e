"""The primal-dual active-set (semismooth Newton) iteration for the regularised friction problem,
with the nodal multipliers as a second unknown (:class:`PrimalDualActiveSet`)."""
from __future__ import annotations

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from damage_dolfinx import compat
from damage_dolfinx.numerics.condensed import BlockUpdateSolver, DiagonalUpdateSolver
from damage_dolfinx.numerics.solvers import ConvergenceError
from damage_dolfinx.numerics.friction import law
from damage_dolfinx.numerics.friction.nodes import JACOBIAN_SHIFT, linear_defaults, near_nullspace
from damage_dolfinx.numerics.friction.residual import AlgebraicResidual

#: 3-D: GMRES iterations above which the lagged LU factorisation of the active-set matrix is
#: rebuilt (condensed.BlockUpdateSolver; the blocks change in every iteration)
LAG_ITS_3D = 30


class PrimalDualActiveSet:
    """Primal-dual active-set (semismooth) Newton for the same regularised problem (2.99)-(2.101)
    (Stadler, SIAM J. Optim. 15, 2004), with the nodal multipliers lambda_i = Phi_eps(v_tau,i)/g_i
    as a second unknown:

        A v - b + sum_i m_i g_i lambda_i tau_i = 0,   max(1, |v_tau,i|/eps) lambda_i = v_tau,i/eps.

    Linearised at (v, lambda) and condensed (lambda eliminated node by node), each iteration is one
    Cholesky solve with A + sum_i K_i tau_i tau_i^T: K_i = m_i g_i/eps on the nodes with
    |v_tau| <= eps, K_i = m_i g_i (1 - lambda_i sgn v_tau,i)/|v_tau,i| on the others (0 once
    lambda_i is consistent, large while it points against the slip). A slip reversal is thus
    damped by the multiplier, where the primal Newton (K_i = 0 on slipping nodes) overshoots and
    its line search needs many iterations per step (2.2-ex1 at k = 0.02; benchmarks/README.md,
    "Why the defaults").
    The stopping test is the primal Newton's: ||F(v)|| of :class:`AlgebraicResidual`.
    Needs axis-parallel tangents (tau tau^T diagonal), like the bilateral contact conditions.

    3-D: lambda_i and v_tau,i are 2-vectors, |.| the Euclidean norm, P the projection
    onto the unit disc; the linearisation of |s| lambda = s on a sliding node gives the 2x2 block
    m g (I - lambda n^T)/|s| (n = s/|s|), not symmetric unless lambda is parallel to n, and the
    multiplier update lambda <- P(lambda + (I - lambda n^T) s_new/|s|) (its fixed point with
    s_new = s is lambda = n). Its symmetric part would keep Cholesky usable but makes the
    multiplier converge linearly (factor 1/2: several times the iterations of the exact block on
    the sliding block of tests/test_tresca_3d.py), so J = A + blocks is assembled and
    solved by GMRES preconditioned with the LU factorisation of an earlier J
    (condensed.BlockUpdateSolver with lag_its)."""

    def __init__(self, residual: "AlgebraicResidual", prefix: str):
        self.residual, self.nodes, self.p = residual, residual.nodes, residual.p
        tau = self.nodes.tau
        comm = self.p.msh.comm
        self._r, self._rhs = residual.b.duplicate(), residual.b.duplicate()
        if self.nodes.dim == 3:
            self.usable, self.rows = True, self.nodes.rows()
            self.free_rows = self._free(self.rows)
            V = self.p.V
            self.solver = BlockUpdateSolver(residual.A, self.rows, self.free_rows, prefix,
                                            linear_defaults(V, symmetric=False),
                                            near_nullspace(V), lag_its=LAG_ITS_3D)
            return
        self.usable = comm.allreduce(bool(np.all(np.abs(tau[:, 0] * tau[:, 1]) < 1e-12)),
                                     op=MPI.LAND)
        self.rows = 2 * self.nodes.dofs + np.argmax(np.abs(tau), axis=1)  # owned tangential dofs
        self.free_rows = self._free(self.rows)
        # J = A + diag(K on the free tangential dofs): no factorisation per new K
        self.solver = DiagonalUpdateSolver(residual.A, np.sort(self.rows[self.free_rows]), prefix)
        self._order = np.argsort(self.rows[self.free_rows])

    def _free(self, rows):
        """False on the rows that carry a Dirichlet condition."""
        free = self.residual.b.duplicate()  # 0 on Dirichlet dofs (ghosted, as set_bc expects)
        with free.localForm() as fl:
            fl.set(1.0)
        compat.set_bc(free, self.p.bcs, scale=0.0)
        mask = free.array[rows] != 0.0
        free.destroy()
        return mask

    def solve_linear(self, K, b, x) -> bool:
        """x = (A + diag(K on the tangential dofs))^{-1} b (direct); False if singular."""
        return self.solver.solve(K[self.free_rows][self._order], b, x)

    def solve(self, x: PETSc.Vec, eps: float, rtol: float, atol: float, max_it: int) -> int:
        """Iterate from x (the previous velocity; lambda consistent with it) until ||F(x)|| <=
        max(rtol ||F(x0)||, atol); returns the iterations, raises ConvergenceError otherwise."""
        if self.nodes.dim == 3:
            return self._solve_3d(x, eps, rtol, atol, max_it)
        nodes, g, gm = self.nodes, self.nodes.g, self.nodes.g * self.nodes.m
        r, rhs = self._r, self._rhs
        self.residual(x, r)
        r0 = r.norm()
        s = nodes.tangential(x)
        lam = np.clip(s / eps, -1.0, 1.0)
        shift = 0.0
        for it in range(1, max_it + 1):
            active = np.abs(s) > eps
            sign, size = np.sign(s), np.maximum(np.abs(s), eps)
            K = np.where(active, gm * (1.0 - lam * sign) / size, gm / eps)
            while True:
                # with ``shift``, a proximal term shift g m (s_new - s) on the sliding nodes
                # (zero at convergence) keeps the matrix regular when no Gamma_D holds the body
                # and every node slides with a consistent multiplier (K = 0)
                self.residual.b.copy(rhs)
                nodes.add_tangential_load(rhs, np.where(active, g * (lam - shift * s), 0.0))
                compat.set_bc(rhs, self.p.bcs)
                if self.solve_linear(K + np.where(active, shift * gm, 0.0), rhs, x):
                    break
                if shift > 0.0:
                    raise ConvergenceError("primal-dual active set: linear solve failed "
                                           "(singular matrix)")
                shift = JACOBIAN_SHIFT
            s_new = nodes.tangential(x)
            lam = np.clip(np.where(active, sign + (1.0 - lam * sign) * (s_new - s) / size,
                                   s_new / eps), -1.0, 1.0)
            s = s_new
            self.residual(x, r)
            if r.norm() <= max(rtol * r0, atol):
                return it
        raise ConvergenceError(f"primal-dual active set: ||F|| = {r.norm():.3e} after {max_it} "
                               f"iterations (start {r0:.3e})")

    def _solve_3d(self, x, eps, rtol, atol, max_it) -> int:
        """The same iteration with 2-vector multipliers (see the class docstring)."""
        nodes, g, gm = self.nodes, self.nodes.g, self.nodes.g * self.nodes.m
        r, rhs = self._r, self._rhs
        eye = np.eye(2)[None]
        self.residual(x, r)
        r0 = r.norm()
        s = nodes.tangential(x)
        lam = law.project(s / eps)
        shift = 0.0
        for it in range(1, max_it + 1):
            active = ~law.stick(s, eps)
            size = np.maximum(law.norm(s), eps)
            n = s / size[:, None]
            ln = np.einsum("it,iu->itu", lam, n)
            slide = (eye - ln) / size[:, None, None]
            K = np.where(active[:, None, None], slide, eye / eps) * gm[:, None, None]
            while True:  # the proximal shift of the 2-D iteration, if the matrix is singular
                self.residual.b.copy(rhs)
                nodes.add_tangential_load(rhs, np.where(active[:, None],
                                                        g[:, None] * (lam - shift * s), 0.0))
                compat.set_bc(rhs, self.p.bcs)
                K_shift = K + np.where(active, shift * gm, 0.0)[:, None, None] * eye
                if self.solver.solve(K_shift, rhs, x):
                    break
                if shift > 0.0:
                    raise ConvergenceError("primal-dual active set: linear solve failed "
                                           "(singular matrix)")
                shift = JACOBIAN_SHIFT
            s_new = nodes.tangential(x)
            lam = law.project(np.where(active[:, None],
                                       lam + np.einsum("itu,iu->it", slide, s_new),
                                       s_new / eps))
            s = s_new
            self.residual(x, r)
            if r.norm() <= max(rtol * r0, atol):
                return it
        raise ConvergenceError(f"primal-dual active set: ||F|| = {r.norm():.3e} after {max_it} "
                               f"iterations (start {r0:.3e})")
