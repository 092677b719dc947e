"""The two thesis baselines for the friction VI, on the unregularised (Uzawa) and regularised
(penalty-duality) problem: a constant operator factorised once, nodal multipliers updated with
NumPy, stopped when ||v_{s+1} - v_s||_V <= tol ||v_{s+1}||_V (thesis: tol = 1e-6).

They serve the reproduction (Tables 2.2-2.4 compare them with Newton on the regularised law)
and are not part of the installed library: importing this module registers them as the
friction solvers ``uzawa`` and ``penalty-duality`` (``friction_solver`` parameter). The command
line imports it when named in ``DAMAGE_DOLFINX_PLUGINS`` (``make`` and the tests do so)."""
from __future__ import annotations

import math
import time

import numpy as np
import ufl
from petsc4py import PETSc

from damage_dolfinx import compat
from damage_dolfinx.forms.constitutive import eps as strain
from damage_dolfinx.core.parameters import InputError
from damage_dolfinx.numerics.solvers import ConvergenceError, set_default_options, spd_direct
from damage_dolfinx.numerics.friction import law
from damage_dolfinx.numerics.friction import register_solver
from damage_dolfinx.numerics.friction.nodes import ContactNodes, FrictionProblem

class ConstantOperator:
    """A constant symmetric matrix assembled and factorised once (Cholesky, options prefix),
    solving for many right-hand sides. Direct in 3-D too: the baselines solve with it hundreds
    to thousands of times per step, where one factorisation beats AMG-preconditioned CG
    (2.2-ex1-3d at n = 12, 6591 unknowns, 5 steps: Uzawa's 6845 solves took 299 s with
    CG + GAMG)."""

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
    """(2.98) with its misprints corrected (docs/models.md, section 2.2):
    a(v_{s+1}, w) + sum_i m_i g_i lambda_{s,i} w_tau,i = l(w);
    lambda_{s+1} = P(lambda_s + rho g v_{s+1,tau}), P(x) = x / max(1, |x|). The multiplier is
    kept between time steps (warm start)."""

    name = "uzawa"

    def __init__(self, problem: FrictionProblem, rho: float, prefix="uzawa_", tol=1e-6, **kw):
        if not rho > 0:
            raise InputError(f"Uzawa step rho_U must be positive, got {rho}")
        super().__init__(problem, problem.a, prefix, tol, **kw)
        self.rho = rho
        self.lam = np.zeros(self.nodes.dofs.size if self.nodes.dim == 2
                            else (self.nodes.dofs.size, 2))

    def _multiplier_force(self):
        if self.nodes.dim == 3:
            return self.nodes.g[:, None] * self.lam
        return self.nodes.g * self.lam

    def _update_multiplier(self, v_tau):
        if self.nodes.dim == 3:  # projection onto the unit disc
            self.lam = law.project(self.lam + self.rho * self.nodes.g[:, None] * v_tau)
            return
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
        v, w = ufl.TrialFunction(problem.V), ufl.TestFunction(problem.V)
        if problem.dim == 2:
            tt = problem.tangent()
            operator = problem.a + omega * ufl.dot(v, tt) * ufl.dot(w, tt) * problem.nodal_ds()
        else:
            operator = problem.a + omega * problem.tangential_product(v, w) * problem.nodal_ds()
        super().__init__(problem, operator, prefix, tol, **kw)
        self.eps_reg, self.omega = eps_reg, omega
        self.q = np.zeros(self.nodes.dofs.size if problem.dim == 2 else (self.nodes.dofs.size, 2))

    def _multiplier_force(self):
        return self.q

    def _update_multiplier(self, v_tau):
        """q = 2 omega (x - y) with y + Phi_eps(y)/omega = 2x, x = v_tau + q/(2 omega)."""
        g, eps_, om = self.nodes.g, self.eps_reg, self.omega
        if self.nodes.dim == 3:
            self.q = self._update_3d(v_tau, g, eps_, om)
            return
        x = v_tau + self.q / (2.0 * om)
        stick = np.abs(2.0 * x) <= eps_ + g / om
        y = np.where(stick, 2.0 * x / (1.0 + g / (om * eps_)), 2.0 * x - np.sign(x) * g / om)
        self.q = 2.0 * om * (x - y)


    def _update_3d(self, v_tau, g, eps_, om):
        """The 2-D update along each node's direction x/|x| (Phi_eps is radial): |y| from
        |y| + g min(|y|/eps, 1)/omega = 2|x|."""
        x = v_tau + self.q / (2.0 * om)
        size = law.norm(x)
        stick = 2.0 * size <= eps_ + g / om
        scale = np.where(stick, 2.0 / (1.0 + g / (om * eps_)),
                         (2.0 * size - g / om) / np.where(stick, 1.0, size))
        return 2.0 * om * (x - scale[:, None] * x)


def _uzawa(problem, eps_reg, rho_uzawa, omega_pd, tol):
    return Uzawa(problem, rho_uzawa, tol=tol)


def _penalty_duality(problem, eps_reg, rho_uzawa, omega_pd, tol):
    return PenaltyDuality(problem, eps_reg, omega_pd, tol=tol)


# Uzawa's operator is singular without Gamma_D (quasistatic), and its ||eps(v)|| stopping test
# cannot see rigid motions (dynamic): it needs a clamped part
register_solver("uzawa", _uzawa, needs_clamp=True)
register_solver("penalty-duality", _penalty_duality)
