"""Second-kind variational inequalities with Tresca friction (velocity step (2.67), increment
step (2.187), dynamic step (3.94)): three interchangeable solvers of the same discrete problem

    v in V:  a(v, w - v) + j(w) - j(v) >= l(w - v)  for all w in V,
    j(w) = sum_i m_i g_i |w_tau,i|   (nodal quadrature of int_{Gamma_C} g |w_tau| ds),

where V already carries v = 0 on Gamma_D and v.nu = 0 on Gamma_C (Dirichlet conditions).

* :class:`RegularisedNewton` (the main solver): SNES Newton on the regularised law Phi_eps
  (2.99)-(2.101) with a backtracking line search on the convex energy
  1/2 a(v,v) - l(v) + j_eps(v) (SNES objective), warm start from the previous step at the target
  eps_reg (1e-9). Each step first tries full Newton steps, then the primal-dual active-set
  iteration on the same equations (:class:`PrimalDualActiveSet`, for steps that reverse the
  slip), then the line search; further fallbacks: an eps continuation (1e-2, 1e-3, ..., target), then the same
  continuation with a Jacobian shift (needed when no Gamma_D holds the body). The residual is
  algebraic (:class:`AlgebraicResidual`: one matrix-vector product per iteration, no assembly);
  linear solves by Cholesky (PETSc's in serial, MUMPS in parallel), re-factorised only when the
  Jacobian changes (i.e. when the stick set changes).
* :class:`Uzawa` (2.98) with the corrections of G8: lambda_{s+1} = P(lambda_s + rho g v_tau),
  P(x) = x / max(1, |x|); the unregularised problem (needs Gamma_D: a must be coercive).
* :class:`PenaltyDuality`: the Bermudez-Moreno iteration on the regularised problem, as in the
  thesis: Phi_eps(v_tau) = omega v_tau + q, q_{s+1} = (G - omega I)_lambda(v_tau + lambda q_s),
  lambda omega = 1/2.

Uzawa and penalty-duality factorise their constant matrix once and update nodal multipliers
with NumPy (no loops over dofs); both stop when ||v_{s+1} - v_s||_V <= tol ||v_{s+1}||_V
(thesis: tol = 1e-6).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from . import compat
from .constitutive import eps as strain
from .contact import F_reg, NODAL_QUADRATURE, Phi_reg, tangent
from .condensed import DiagonalUpdatePC, DiagonalUpdateSolver
from .parameters import InputError
from .solvers import (NEWTON, ConvergenceError, NonlinearSolver, SolveContext,
                      replace_default_option, set_default_options, spd_direct)

#: relative Jacobian shift on contact nodes (units of g per unit slip velocity)
JACOBIAN_SHIFT = 1e-3
#: enables the lagged factorisation (NonlinearSolver); with a direct KSP it is rebuilt exactly
#: when the Jacobian changes
REFACTOR_ITS = 10

SOLVERS = ("newton", "uzawa", "penalty-duality")
#: the first attempt of each step: full Newton steps (no energy evaluations), at most this many
FAST_MAX_IT = 6
#: after a failed first attempt, go straight to the energy line search for this many steps
FAST_PAUSE_STEPS = 10
#: iterations of the primal-dual active-set attempt before the line-search Newton takes over
#: (PETSc option -<prefix>pdas_max_it, e.g. -friction_pdas_max_it 0 to skip the attempt)
PDAS_MAX_IT = 50


@dataclass
class FrictionProblem:
    """Data of one second-kind VI: the unknown ``v``, bilinear ``a`` (UFL, trial/test of V),
    linear ``l`` (UFL, test), Dirichlet ``bcs``, friction bound ``g`` (UFL scalar), the contact
    measure ``dsC`` (ds restricted to Gamma_C) and the solve context."""
    v: fem.Function
    a: object
    l: object
    bcs: list
    g: object
    dsC: object
    context: SolveContext

    @property
    def V(self):
        return self.v.function_space

    @property
    def msh(self):
        return self.V.mesh

    def nodal_ds(self):
        return self.dsC(metadata=NODAL_QUADRATURE)

    def tangent(self):
        return tangent(ufl.FacetNormal(self.msh))


class ContactNodes:
    """Owned vertices of Gamma_C with their lumped weights m_i, unit tangents tau_i and friction
    bounds g_i, all from nodal-quadrature boundary integrals (valid on any straight sides)."""

    def __init__(self, problem: FrictionProblem):
        V, msh = problem.V, problem.msh
        S = compat.scalar_p1(msh)
        phi, w = ufl.TestFunction(S), ufl.TestFunction(V)
        ds = problem.nodal_ds()
        n_owned = S.dofmap.index_map.size_local
        m = _assembled(phi * ds)[:n_owned]
        gm = _assembled(problem.g * phi * ds)[:n_owned]
        tm = _assembled(ufl.dot(problem.tangent(), w) * ds).reshape(-1, 2)[:n_owned]
        self.dofs = np.flatnonzero(m > 0)
        if not np.allclose(S.tabulate_dof_coordinates()[self.dofs],
                           V.tabulate_dof_coordinates()[self.dofs]):
            raise RuntimeError("scalar and vector P1 dof numberings differ")  # never seen
        self.m = m[self.dofs]
        self.g = gm[self.dofs] / self.m
        tau = tm[self.dofs] / self.m[:, None]
        self.tau = tau / np.linalg.norm(tau, axis=1)[:, None]

    def tangential(self, v):
        """v_tau at the contact nodes (owned); ``v`` a Function or a PETSc Vec."""
        array = v.x.array if hasattr(v, "x") else v.getArray(readonly=True)
        return np.einsum("ic,ic->i", array.reshape(-1, 2)[self.dofs], self.tau)

    def add_tangential_load(self, b: PETSc.Vec, force):
        """b_i -= m_i force_i tau_i on the owned contact nodes (the nodal integral of force w_tau)."""
        arr = b.getArray().reshape(-1, 2)  # owned part
        arr[self.dofs] -= (self.m * force)[:, None] * self.tau
        b.setArray(arr.reshape(-1))


def _assembled(L) -> np.ndarray:
    """Local array (owned + ghost values summed across ranks) of an assembled linear form."""
    f = compat.form(L)
    b = compat.create_vector(f)
    with b.localForm() as bl:
        bl.set(0.0)
    compat.assemble_vector(b, f)
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    b.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
    with b.localForm() as bl:
        return bl.array.copy()


class ConstantOperator:
    """A constant symmetric matrix assembled and factorised once (Cholesky, options prefix),
    solving for many right-hand sides."""

    def __init__(self, a, bcs, prefix, context):
        self.a = compat.form(a)
        self.A = compat.create_matrix(self.a)
        compat.assemble_matrix(self.A, self.a, bcs)
        self.A.assemble()
        self.prefix, self.context = prefix, context
        set_default_options(prefix, spd_direct(self.A.getComm().tompi4py()))
        self.ksp = PETSc.KSP().create(self.A.getComm())
        self.ksp.setOptionsPrefix(prefix)
        self.ksp.setOperators(self.A)
        self.ksp.setFromOptions()

    def solve(self, b, x):
        self.ksp.solve(b, x)
        if self.ksp.getConvergedReason() < 0:
            raise ConvergenceError(
                f"{self.prefix}ksp failed ({self.ksp.getConvergedReason()}) "
                f"{self.context.where()}, residual {self.ksp.getResidualNorm():.3e}")


class _IterativeFrictionSolver:
    """Shared part of Uzawa and penalty-duality: rhs l assembled once per step, a constant
    factorised operator, V-norm increments, the stopping test."""

    name = "?"

    def __init__(self, problem: FrictionProblem, operator_form, prefix, tol=1e-6, max_it=20000):
        self.p, self.tol, self.max_it = problem, tol, max_it
        self.nodes = ContactNodes(problem)
        self.op = ConstantOperator(operator_form, problem.bcs, prefix, problem.context)
        self.l = compat.form(problem.l)
        self.b0 = compat.create_vector(self.l)
        self.b = self.b0.duplicate()
        V = problem.V
        u, w = ufl.TrialFunction(V), ufl.TestFunction(V)
        k_eps = compat.form(ufl.inner(strain(u), strain(w)) * ufl.dx)
        self.K_eps = compat.create_matrix(k_eps)
        compat.assemble_matrix(self.K_eps, k_eps, [])
        self.K_eps.assemble()
        self._work = self.b0.duplicate()
        self.iterations = 0
        self.solves = 0
        self.timings = {"solve": 0.0}

    def _v_norm(self, x):
        self.K_eps.mult(x, self._work)
        return math.sqrt(max(x.dot(self._work), 0.0))

    def solve(self) -> int:
        start = time.perf_counter()
        with self.b0.localForm() as bl:
            bl.set(0.0)
        compat.assemble_vector(self.b0, self.l)
        compat.apply_lifting(self.b0, self.op.a, self.p.bcs)  # non-zero Dirichlet values
        self.b0.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        x = compat.petsc_vec(self.p.v)
        previous = x.copy()
        for s in range(1, self.max_it + 1):
            self.b0.copy(self.b)
            self.nodes.add_tangential_load(self.b, self._multiplier_force())
            compat.set_bc(self.b, self.p.bcs)
            self.op.solve(self.b, x)
            x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
            self._update_multiplier(self.nodes.tangential(self.p.v))
            previous.axpy(-1.0, x)
            change, size = self._v_norm(previous), self._v_norm(x)
            x.copy(previous)
            if change <= self.tol * max(size, 1e-300):
                break
        else:
            raise ConvergenceError(f"{self.name} did not converge in {self.max_it} iterations "
                                   f"{self.p.context.where()}, relative V-change "
                                   f"{change / max(size, 1e-300):.3e}")
        self.iterations += s
        self.solves += 1
        self.timings["solve"] += time.perf_counter() - start
        return s


class Uzawa(_IterativeFrictionSolver):
    """(2.98) with G8: a(v_{s+1}, w) + sum_i m_i g_i lambda_{s,i} w_tau,i = l(w);
    lambda_{s+1} = P(lambda_s + rho g v_{s+1,tau}), P(x) = x / max(1, |x|). The multiplier is
    kept between time steps (warm start)."""

    name = "uzawa"

    def __init__(self, problem: FrictionProblem, rho: float, prefix="uzawa_", tol=1e-6, **kw):
        if not rho > 0:
            raise InputError(f"Uzawa step rho_U must be positive, got {rho}")
        super().__init__(problem, problem.a, prefix, tol, **kw)
        self.rho = rho
        self.lam = np.zeros(self.nodes.dofs.size)

    def _multiplier_force(self):
        return self.nodes.g * self.lam

    def _update_multiplier(self, v_tau):
        x = self.lam + self.rho * self.nodes.g * v_tau
        self.lam = x / np.maximum(1.0, np.abs(x))


class PenaltyDuality(_IterativeFrictionSolver):
    """Bermudez-Moreno on the regularised law: a(v, w) + sum_i m_i (omega v_tau,i + q_i) w_tau,i
    = l(w) with q = (Phi_eps - omega I)_lambda(v_tau + lambda q), lambda = 1/(2 omega)."""

    name = "penalty-duality"

    def __init__(self, problem: FrictionProblem, eps_reg: float, omega: float,
                 prefix="pd_", tol=1e-6, **kw):
        if not omega > 0:
            raise InputError(f"penalty-duality omega must be positive, got {omega}")
        v, w, tt = ufl.TrialFunction(problem.V), ufl.TestFunction(problem.V), problem.tangent()
        operator = problem.a + omega * ufl.dot(v, tt) * ufl.dot(w, tt) * problem.nodal_ds()
        super().__init__(problem, operator, prefix, tol, **kw)
        self.eps_reg, self.omega = eps_reg, omega
        self.q = np.zeros(self.nodes.dofs.size)

    def _multiplier_force(self):
        return self.q

    def _update_multiplier(self, v_tau):
        """q = 2 omega (x - y) with y + Phi_eps(y)/omega = 2x, x = v_tau + q/(2 omega)."""
        g, eps_, om = self.nodes.g, self.eps_reg, self.omega
        x = v_tau + self.q / (2.0 * om)
        stick = np.abs(2.0 * x) <= eps_ + g / om
        y = np.where(stick, 2.0 * x / (1.0 + g / (om * eps_)), 2.0 * x - np.sign(x) * g / om)
        self.q = 2.0 * om * (x - y)


#: SNES defaults of the friction Newton: line search on the convex energy (objective)
#: (rtol 1e-9: the energy line search cannot certify decreases below ~1e-16 |energy|, which
#: a tighter residual test would ask for)
FRICTION_NEWTON = {**NEWTON, "snes_linesearch_type": "bt", "snes_max_it": 100,
                   "snes_rtol": 1e-9, "snes_atol": 1e-10, "snes_stol": 1e-14}


class AlgebraicResidual:
    """The residual of the regularised problem (2.99) without form assembly:

        F(v) = A v - b + sum_i m_i Phi_eps(v_tau,i) tau_i   (Dirichlet rows: v - v_D),

    A the matrix of the constant form ``a`` (Dirichlet rows and columns eliminated, assembled
    once), b the lifted right-hand side ``l`` (assembled once per time step by
    :meth:`assemble_rhs`), the friction forces nodal (ContactNodes). One matrix-vector product
    per Newton iteration instead of an assembly over all cells. It equals the assembled UFL
    residual where Gamma_C is straight; :meth:`matches` checks that."""

    def __init__(self, problem: FrictionProblem, nodes: ContactNodes, eps: fem.Constant):
        self.p, self.nodes, self.eps = problem, nodes, eps
        self.a, self.l = compat.form(problem.a), compat.form(problem.l)
        self.A = compat.create_matrix(self.a)
        compat.assemble_matrix(self.A, self.a, problem.bcs)
        self.A.assemble()
        self.b = compat.create_vector(self.l)
        self._v = compat.petsc_vec(problem.v)
        self._work = [self.b.duplicate() for _ in range(3)]  # energy_change: d, s, A d

    def assemble_rhs(self):
        with self.b.localForm() as bl:
            bl.set(0.0)
        compat.assemble_vector(self.b, self.l)
        compat.apply_lifting(self.b, self.a, self.p.bcs)
        self.b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        compat.set_bc(self.b, self.p.bcs)

    def __call__(self, x, r):
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        x.copy(self._v)  # the (UFL) Jacobian is assembled from v
        self.p.v.x.scatter_forward()
        self.A.mult(x, r)
        r.axpy(-1.0, self.b)
        phi = self.nodes.g * np.clip(self.nodes.tangential(x) / self.eps.value, -1.0, 1.0)
        self.nodes.add_tangential_load(r, -phi)
        compat.set_bc(r, self.p.bcs, x, -1.0)

    def energy_change(self, x, x0) -> float:
        """E(x) - E(x0) of the convex energy 1/2 a(v,v) - l(v) + j_eps(v) whose gradient is this
        residual: 1/2 (x + x0)^T A (x - x0) - b^T (x - x0) + sum_i m_i (F_eps(x_tau,i) -
        F_eps(x0_tau,i)) (2.101), without cancellation against the large |E|."""
        d, s, Ad = self._work
        x.copy(d)
        d.axpy(-1.0, x0)
        x.copy(s)
        s.axpy(1.0, x0)
        self.A.mult(d, Ad)
        quadratic = 0.5 * s.dot(Ad) - self.b.dot(d)
        eps, g, m = float(self.eps.value), self.nodes.g, self.nodes.m

        def potential(r):
            a = np.abs(r)
            return g * np.where(a <= eps, r * r / (2.0 * eps), a - eps / 2.0)
        local = float(np.sum(m * (potential(self.nodes.tangential(x))
                                  - potential(self.nodes.tangential(x0)))))
        return quadratic + self.p.msh.comm.allreduce(local)

    def matches(self, form_residual, rtol=1e-10) -> bool:
        """True if this residual equals the assembled one (``form_residual``) at two test
        velocities, one slipping and one near the stick threshold, on every rank."""
        saved = self.p.v.x.array.copy()
        X = self.p.V.tabulate_dof_coordinates()[:, :2]
        pattern = np.column_stack([np.sin(3.0 * X[:, 0] + 1.0) + np.cos(5.0 * X[:, 1]),
                                   np.cos(2.0 * X[:, 0]) - np.sin(4.0 * X[:, 1] + 0.5)]).ravel()
        self.assemble_rhs()
        x, r1, r2 = self._v.copy(), self.b.duplicate(), self.b.duplicate()
        worst = 0.0
        for scale in (1.0, 2.0 * float(self.eps.value)):
            with x.localForm() as xl:
                xl.array[:] = scale * pattern
            self(x, r1)
            form_residual(x, r2)
            r1.axpy(-1.0, r2)
            worst = max(worst, r1.norm(PETSc.NormType.INFINITY)
                        / max(r2.norm(PETSc.NormType.INFINITY), 1e-300))
        self.p.v.x.array[:] = saved
        return worst <= rtol


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
    its line search needs 10-100 iterations per step (2.2-ex1 at k = 0.02, benchmarks/README.md).
    The stopping test is the primal Newton's: ||F(v)|| of :class:`AlgebraicResidual`.
    Needs axis-parallel tangents (tau tau^T diagonal), like the bilateral contact conditions."""

    def __init__(self, residual: "AlgebraicResidual", prefix: str):
        self.residual, self.nodes, self.p = residual, residual.nodes, residual.p
        tau = self.nodes.tau
        comm = self.p.msh.comm
        self.usable = comm.allreduce(bool(np.all(np.abs(tau[:, 0] * tau[:, 1]) < 1e-12)),
                                     op=MPI.LAND)
        self.rows = 2 * self.nodes.dofs + np.argmax(np.abs(tau), axis=1)  # owned tangential dofs
        free = residual.b.duplicate()  # 0 on Dirichlet dofs (ghosted, as set_bc expects)
        with free.localForm() as fl:
            fl.set(1.0)
        compat.set_bc(free, self.p.bcs, scale=0.0)
        self.free_rows = free.array[self.rows] != 0.0
        free.destroy()
        self._r, self._rhs = residual.b.duplicate(), residual.b.duplicate()
        # J = A + diag(K on the free tangential dofs): no factorisation per new K (issue 18)
        self.solver = DiagonalUpdateSolver(residual.A, np.sort(self.rows[self.free_rows]), prefix)
        self._order = np.argsort(self.rows[self.free_rows])

    def solve_linear(self, K, b, x) -> bool:
        """x = (A + diag(K on the tangential dofs))^{-1} b (direct); False if singular."""
        return self.solver.solve(K[self.free_rows][self._order], b, x)

    def solve(self, x: PETSc.Vec, eps: float, rtol: float, atol: float, max_it: int) -> int:
        """Iterate from x (the previous velocity; lambda consistent with it) until ||F(x)|| <=
        max(rtol ||F(x0)||, atol); returns the iterations, raises ConvergenceError otherwise."""
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


class RegularisedNewton:
    """Newton on the regularised optimality equation (2.99)-(2.101):
    a(v, w) + sum_i m_i Phi_eps(v_tau,i) w_tau,i = l(w), eps = eps_reg (thesis 1e-9)."""

    name = "newton"

    def __init__(self, problem: FrictionProblem, eps_reg=1e-9, prefix="friction_",
                 continuation=(1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)):
        msh, v = problem.msh, problem.v
        self.p, self.target = problem, float(eps_reg)
        self.continuation = [e for e in continuation if e > self.target] + [self.target]
        self.eps = fem.Constant(msh, self.target)
        w, tt, ds = ufl.TestFunction(problem.V), problem.tangent(), problem.nodal_ds()
        v_tau = ufl.dot(v, tt)
        F = ufl.action(problem.a, v) - problem.l + Phi_reg(v_tau, problem.g, self.eps) * ufl.dot(w, tt) * ds
        dv = ufl.TrialFunction(problem.V)
        # Jacobian of Phi_eps plus a shift (only during the eps continuation) of
        # JACOBIAN_SHIFT*g on every contact node: slipping nodes contribute 0 to the exact
        # Jacobian, so with no Gamma_D (2.2 Ex. 3) and all nodes slipping it is singular; the
        # shift keeps Newton directions defined and descending (the residual, hence the
        # solution, is unchanged)
        self.shift = fem.Constant(msh, 0.0)
        J = (ufl.derivative(F, v, dv)
             + self.shift * problem.g * ufl.dot(dv, tt) * ufl.dot(w, tt) * ds)
        # objective: the energy relative to the solve's starting point v0, written without
        # cancellation, E(v) - E(v0) = 1/2 a(v + v0, v - v0) - l(v - v0) + j_eps(v) - j_eps(v0):
        # the line search then resolves decreases relative to |v - v0|, not to |E| (which the
        # explicit elastic load makes large)
        self.nodes = ContactNodes(problem)
        self.v0 = fem.Function(problem.V)
        d, s_ = v - self.v0, v + self.v0
        test, trial = sorted(problem.a.arguments(), key=lambda arg: arg.number())
        energy = (0.5 * ufl.replace(problem.a, {trial: s_, test: d})
                  - ufl.replace(problem.l, {problem.l.arguments()[0]: d})
                  + (F_reg(v_tau, problem.g, self.eps)
                     - F_reg(ufl.dot(self.v0, tt), problem.g, self.eps)) * ds)
        self._energy = compat.form(energy)
        self.residual = AlgebraicResidual(problem, self.nodes, self.eps)
        self.newton = NonlinearSolver(F, v, problem.bcs, prefix, problem.context,
                                      defaults={**FRICTION_NEWTON, **spd_direct(msh.comm)},
                                      refactor_after_its=REFACTOR_ITS, J=J,
                                      jacobian_key=self._stick_set, residual=self.residual)
        # the assembled residual where the nodal one is not exact (a bent Gamma_C)
        self.algebraic = True
        if not self.residual.matches(self.newton.form_residual):
            self.use_form_residual()
        pdas = PrimalDualActiveSet(self.residual, prefix + "pdas_") if self.algebraic else None
        self.pdas = pdas if pdas is not None and pdas.usable else None
        self.pdas_iterations = self.pdas_solves = self.pdas_failures = 0
        self.prefix = prefix
        # Newton's linear solves by the active-set iteration's DiagonalUpdateSolver where the
        # Jacobian is A + diag(K(stick set)) (checked): no assembly and no factorisation per
        # new stick set (issue 18)
        self.condensed = self.pdas is not None and self._condense_newton(J)
        newton_solve = self.newton.solve

        def solve_from_here():
            self.v0.x.array[:] = v.x.array
            return newton_solve()
        self.newton.solve = solve_from_here
        self.snes = self.newton.snes
        self.snes.snes.setObjective(self._objective)
        self.iterations = 0
        self.solves = 0
        self.continuations = self.shifted_continuations = self.full_step_solves = 0
        self.fast_failures, self._fast_pause = 0, 0
        self.timings = {"solve": 0.0}

    def _newton_K(self, x):
        """The Jacobian's diagonal on the free tangential contact dofs at x: m g (1/eps on the
        stick nodes |v_tau/eps| <= 1, as UFL differentiates clip, plus the shift)."""
        eps = float(self.eps.value)
        t = self.nodes.tangential(x) / eps
        K = self.nodes.g * self.nodes.m * (np.where((t <= 1.0) & (t >= -1.0), 1.0 / eps, 0.0)
                                           + float(self.shift.value))
        return K[self.pdas.free_rows][self.pdas._order]

    def _condense_newton(self, J) -> bool:
        """Route the Newton KSP through a DiagonalUpdatePC with K = _newton_K(iterate), unless
        the user chose the friction linear solver or the algebraic Jacobian differs from the
        assembled UFL one (checked at a slipping and a stick/slip velocity, shift off and on)."""
        comm, key = self.p.msh.comm, self.prefix + "pc_type"
        if PETSc.Options().getString(key, "") != spd_direct(comm)["pc_type"]:
            return False
        if not self._jacobian_matches(J):
            return False
        pc = DiagonalUpdatePC(self.pdas.solver)
        replace_default_option(key, "python")  # setFromOptions keeps the Python PC
        snes = self.newton.snes.snes
        pc.attach(snes.getKSP())
        snes.setJacobian(lambda snes_, x, A_, P_: pc.set_K(self._newton_K(x)), pc.operator,
                         pc.operator)
        return True

    def _jacobian_matches(self, J, rtol=1e-10) -> bool:
        """True if the assembled UFL Jacobian equals A + diag(_newton_K) on every rank."""
        v, A = self.p.v, self.residual.A
        form = compat.form(J)
        M = compat.create_matrix(form)
        d = A.createVecLeft()
        rows = np.sort(self.pdas.rows[self.pdas.free_rows])
        saved = v.x.array.copy()
        X = self.p.V.tabulate_dof_coordinates()[:, :2]
        pattern = np.column_stack([np.sin(3.0 * X[:, 0] + 1.0) + np.cos(5.0 * X[:, 1]),
                                   np.cos(2.0 * X[:, 0]) - np.sin(4.0 * X[:, 1] + 0.5)]).ravel()
        worst = 0.0
        for scale in (1.0, 2.0 * self.target):
            for shift in (0.0, JACOBIAN_SHIFT):
                v.x.array[:] = scale * pattern
                self.shift.value = shift
                M.zeroEntries()
                compat.assemble_matrix(M, form, self.p.bcs)
                M.assemble()
                size = M.norm(PETSc.NormType.INFINITY)
                d.set(0.0)
                d.array[rows] = -self._newton_K(compat.petsc_vec(v))
                M.axpy(-1.0, A, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
                M.setDiagonal(d, addv=PETSc.InsertMode.ADD_VALUES)
                worst = max(worst, M.norm(PETSc.NormType.INFINITY) / max(size, 1e-300))
        v.x.array[:] = saved
        self.shift.value = 0.0
        M.destroy()
        d.destroy()
        return self.p.msh.comm.allreduce(worst, op=MPI.MAX) <= rtol

    def use_form_residual(self):
        """Assemble the UFL residual in every Newton iteration (instead of AlgebraicResidual)."""
        self.algebraic = False
        self.newton.snes.snes.setFunction(lambda snes, x, f: self.newton.form_residual(x, f),
                                          self.residual.b.duplicate())

    def _fast_attempt(self) -> bool:
        """Full Newton steps (basic line search: one residual per iteration, no energy) from
        the previous velocity, at most FAST_MAX_IT iterations; False if skipped or failed (v is
        then unchanged). Skipped for FAST_PAUSE_STEPS steps after a failure (stick-slip
        phases, where it rarely succeeds)."""
        if self._fast_pause > 0:
            self._fast_pause -= 1
            return False

        def solve():
            self.snes.snes.setTolerances(max_it=FAST_MAX_IT)
            return self.newton.solve()
        try:
            self._with_line_search("basic", solve)
            return True
        except ConvergenceError:
            self.fast_failures += 1
            self._fast_pause = FAST_PAUSE_STEPS
            return False

    def _pdas_attempt(self) -> bool:
        """The primal-dual active-set iteration from the previous velocity (PrimalDualActiveSet),
        to the SNES tolerances; False if unavailable or failed (v is then unchanged)."""
        max_it = PETSc.Options().getInt(self.prefix + "pdas_max_it", PDAS_MAX_IT)
        if self.pdas is None or max_it <= 0:
            return False
        x = compat.petsc_vec(self.p.v)
        saved = x.copy()
        rtol, atol, _, _ = self.snes.snes.getTolerances()
        try:
            self.pdas_iterations += self.pdas.solve(x, self.target, rtol, atol, max_it)
            self.pdas_solves += 1
            return True
        except ConvergenceError:
            saved.copy(x)
            self.pdas_failures += 1
            return False
        finally:
            saved.destroy()
            self.p.v.x.scatter_forward()

    def _with_line_search(self, kind, fn):
        opts, key = PETSc.Options(), self.prefix + "snes_linesearch_type"
        previous = opts.getString(key, "bt")
        opts[key] = kind
        self.snes.snes.setFromOptions()
        try:
            return fn()
        finally:
            opts[key] = previous
            self.snes.snes.setFromOptions()

    def _stick_set(self, x):
        """What the Jacobian depends on besides constants: eps, the shift and the nodes with
        |v_tau| <= eps (nodal quadrature), read from the SNES iterate x."""
        v = x.getArray(readonly=True).reshape(-1, 2)[self.nodes.dofs]
        stick = np.abs(np.einsum("ic,ic->i", v, self.nodes.tau)) <= self.eps.value
        return np.concatenate([[float(self.eps.value), float(self.shift.value)], stick])

    def _continuation(self, shifted=False):
        """Solve for eps = 1e-2, 1e-4, ..., target, each from the previous solution; with
        ``shifted`` the Jacobian shift is on for all but the final (target) stage, so that the
        last Newton iterations are exact."""
        try:
            for e in self.continuation:
                self.eps.value = e
                self.shift.value = JACOBIAN_SHIFT if shifted and e != self.target else 0.0
                self.newton.solve()
        finally:
            self.shift.value = 0.0

    def _objective(self, snes, x):
        """E(x) - E(v0) (the line search's merit function): algebraic when the residual is."""
        if self.algebraic:
            return self.residual.energy_change(x, compat.petsc_vec(self.v0))
        x.copy(compat.petsc_vec(self.p.v))
        self.p.v.x.scatter_forward()
        return compat.assemble_scalar(self._energy, self.p.msh.comm)

    def solve(self) -> int:
        """Full Newton steps at the target eps from the previous velocity, else the primal-dual
        active-set iteration, else Newton with backtracking on the energy; on failure an eps continuation 1e-2, 1e-3, ... -> target with warm starts; on failure again the same
        continuation with the Jacobian shift on its non-final stages; last, full Newton steps.
        Returns this step's Newton iterations."""
        start = time.perf_counter()
        before = self.snes.iterations + self.pdas_iterations
        self.eps.value = self.target
        if self.algebraic:
            self.residual.assemble_rhs()
        try:
            # full Newton steps; then the primal-dual active set; then the energy line search
            if not self._fast_attempt() and not self._pdas_attempt():
                self.newton.solve()
        except ConvergenceError:
            self.continuations += 1  # v is unchanged: restart with eps continuation
            try:
                self._continuation()
            except ConvergenceError:
                self.shifted_continuations += 1  # with the Jacobian shift
                try:
                    self._continuation(shifted=True)
                except ConvergenceError:
                    # last resort: full Newton steps at the target eps from the last stage's start
                    # (the energy line search cannot certify decreases below round-off, which
                    # near convergence at large |energy| stalls it)
                    self.full_step_solves += 1
                    self._with_line_search("basic", self.newton.solve)
        its = self.snes.iterations + self.pdas_iterations - before
        self.iterations += its
        self.solves += 1
        self.timings["solve"] += time.perf_counter() - start
        return its


def iteration_counters(solver) -> dict:
    """The friction solver's fallback counters for summary.json (zeros for Uzawa and PD)."""
    return {f"friction_{name}": getattr(solver, name, 0)
            for name in ("continuations", "shifted_continuations", "full_step_solves",
                         "pdas_solves", "pdas_iterations", "pdas_failures")}


def solver_from_parameters(problem: FrictionProblem, extra: dict, facet_tags, gamma_D: int,
                           example_id: str):
    """The solver named by ``extra["friction_solver"]`` with its parameters from ``extra``
    (eps_reg, rho_uzawa, omega_pd, friction_tol). Uzawa is refused without a clamped part
    Gamma_D: its operator is then singular (quasistatic) or its ||eps(v)|| stopping test cannot
    see rigid motions (dynamic)."""
    kind = extra["friction_solver"]
    comm = problem.msh.comm
    if kind == "uzawa" and comm.allreduce(int(np.sum(facet_tags.values == gamma_D))) == 0:
        raise InputError(f"{example_id}: the Uzawa friction solver needs a clamped part Gamma_D "
                         "(without it its operator is singular or its ||eps(v)|| stopping test "
                         "cannot see rigid motions); use newton or penalty-duality")
    return make_solver(kind, problem, extra["eps_reg"], extra.get("rho_uzawa", 1.0),
                       extra.get("omega_pd", 100.0), extra.get("friction_tol", 1e-6))


def make_solver(kind: str, problem: FrictionProblem, eps_reg: float, rho_uzawa: float,
                omega_pd: float, tol: float = 1e-6):
    """The friction solver selected by ``kind`` (newton | uzawa | penalty-duality)."""
    if kind == "newton":
        return RegularisedNewton(problem, eps_reg)
    if kind == "uzawa":
        return Uzawa(problem, rho_uzawa, tol=tol)
    if kind == "penalty-duality":
        return PenaltyDuality(problem, eps_reg, omega_pd, tol=tol)
    raise InputError(f"unknown friction solver {kind!r}; choose one of {', '.join(SOLVERS)}")
