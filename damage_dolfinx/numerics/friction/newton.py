"""The main friction solver: Newton on the regularised law Phi_eps (2.99)-(2.101) with its chain
of attempts (full steps, the primal-dual active set, the energy line search, eps continuations)
(:class:`RegularisedNewton`)."""
from __future__ import annotations

import time

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from damage_dolfinx import compat
from damage_dolfinx.numerics.held_data import AssembledFrom, held
from damage_dolfinx.numerics.condensed import BlockUpdateSolver, DiagonalUpdatePC
from damage_dolfinx.forms.contact import F_reg, F_reg_vector, Phi_reg, Phi_reg_vector
from damage_dolfinx.numerics.solvers import (NEWTON, ConvergenceError, NonlinearSolver, replace_default_option,
                       spd_direct)
from damage_dolfinx.numerics.friction.active_set import PrimalDualActiveSet
from damage_dolfinx.numerics.friction.nodes import (JACOBIAN_SHIFT, ContactNodes, FrictionProblem, linear_defaults,
                    near_nullspace, newton_linear)
from damage_dolfinx.numerics.friction import law
from damage_dolfinx.numerics.friction.residual import AlgebraicResidual, test_pattern

#: enables the lagged factorisation (NonlinearSolver); with a direct KSP it is rebuilt exactly
#: when the Jacobian changes
REFACTOR_ITS = 10
#: 3-D: the Newton systems J = A + blocks are solved by CG preconditioned with the Cholesky
#: factorisation of an earlier J, rebuilt when the stick set changes or CG needed more than this
#: many iterations (a sliding node's block changes in every iteration; a factorisation of a 3-D
#: J costs as much as many CG iterations, each a triangular solve)
LAG_MAX_ITS_3D = 30

#: the first attempt of each step: full Newton steps (no energy evaluations), at most this many
FAST_MAX_IT = 6
#: after a failed first attempt, go straight to the energy line search for this many steps
FAST_PAUSE_STEPS = 10
#: iterations of the primal-dual active-set attempt before the line-search Newton takes over
#: (PETSc option -<prefix>pdas_max_it, e.g. -friction_pdas_max_it 0 to skip the attempt)
PDAS_MAX_IT = 50


#: SNES defaults of the friction Newton: line search on the convex energy (objective)
#: (rtol 1e-9: the energy line search cannot certify decreases below ~1e-16 |energy|, which
#: a tighter residual test would ask for)
FRICTION_NEWTON = {**NEWTON, "snes_linesearch_type": "bt", "snes_max_it": 100,
                   "snes_rtol": 1e-9, "snes_atol": 1e-10, "snes_stol": 1e-14}



class RegularisedNewton:
    """Newton on the regularised optimality equation (2.99)-(2.101):
    a(v, w) + sum_i m_i Phi_eps(v_tau,i) w_tau,i = l(w), eps = eps_reg (thesis 1e-9).

    An operator ``a`` that holds Functions (of the state) is assembled, with the residual and
    the Jacobian, at every Newton iteration; otherwise its matrix is kept (the algebraic
    residual, the active-set iteration, the condensed Jacobian)."""

    #: an ``a`` holding Functions is assembled where it can have changed (make_solver checks)
    assembles_operator_of_state = True

    name = "newton"
    #: its solve evaluates a bound of the state itself (make_solver wraps other solvers)
    refreshes_bound = True

    def __init__(self, problem: FrictionProblem, eps_reg=1e-9, prefix="friction_",
                 continuation=(1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)):
        msh, v = problem.msh, problem.v
        self.p, self.target = problem, float(eps_reg)
        self.continuation = [e for e in continuation if e > self.target] + [self.target]
        self.eps = fem.Constant(msh, self.target)
        # the test and trial functions of the problem's own forms (not new ones: a form that
        # mixes two Arguments of the same number is refused by UFL, so a solver built again
        # from the same FrictionProblem must not bring its own)
        w, dv = sorted(problem.a.arguments(), key=lambda arg: arg.number())
        ds = problem.nodal_ds()
        self.v0 = fem.Function(problem.V)
        self.shift = fem.Constant(msh, 0.0)
        F, shift_term, friction_change = self._friction_forms(problem, w, dv)
        # Jacobian of Phi_eps plus a shift (only during the eps continuation) of
        # JACOBIAN_SHIFT*g on every contact node: slipping nodes contribute 0 to the exact
        # Jacobian, so with no Gamma_D (2.2 Ex. 3) and all nodes slipping it is singular; the
        # shift keeps Newton directions defined and descending (the residual, hence the
        # solution, is unchanged)
        J = ufl.derivative(F, v, dv) + shift_term * ds
        # objective: the energy relative to the solve's starting point v0, written without
        # cancellation, E(v) - E(v0) = 1/2 a(v + v0, v - v0) - l(v - v0) + j_eps(v) - j_eps(v0):
        # the line search then resolves decreases relative to |v - v0|, not to |E| (which the
        # explicit elastic load makes large)
        self.nodes = ContactNodes(problem)
        d, s_ = v - self.v0, v + self.v0
        test, trial = sorted(problem.a.arguments(), key=lambda arg: arg.number())
        energy = (0.5 * ufl.replace(problem.a, {trial: s_, test: d})
                  - ufl.replace(problem.l, {problem.l.arguments()[0]: d})
                  + friction_change * ds)
        self._energy = compat.form(energy)
        self.residual = AlgebraicResidual(problem, self.nodes, self.eps)
        # an operator a of the state (Functions in it, e.g. a damage-dependent viscosity or an
        # implicit contact stiffness): a, hence the residual and the Jacobian, assembled at
        # every Newton iteration (the algebraic residual, the active-set iteration and the
        # condensed Jacobian all keep the matrix of a from one solve to the next)
        a_functions, _ = held(problem.a)
        self.operator_of_state = bool(a_functions)
        self._a_constants = AssembledFrom(problem.a, msh.comm, functions=False)
        self.newton = NonlinearSolver(F, v, problem.bcs, prefix, problem.context,
                                      defaults={**FRICTION_NEWTON, **newton_linear(problem.V)},
                                      refactor_after_its=REFACTOR_ITS, J=J,
                                      jacobian_key=None if self.operator_of_state
                                      else self._stick_set, residual=self.residual)
        # the assembled residual where the nodal one is not exact (a bent Gamma_C)
        self.algebraic = True
        if self.operator_of_state or not self.residual.matches(self.newton.form_residual):
            self.use_form_residual()
        pdas = PrimalDualActiveSet(self.residual, prefix + "pdas_") if self.algebraic else None
        self.pdas = pdas if pdas is not None and pdas.usable else None
        self.pdas_iterations = self.pdas_solves = self.pdas_failures = 0
        self.prefix = prefix
        # Newton's linear solves by the active-set iteration's DiagonalUpdateSolver where the
        # Jacobian is A + diag(K(stick set)) (checked): no assembly and no factorisation per
        # new stick set
        # 3-D: the Jacobian A + 2x2 blocks assembled algebraically (checked against UFL's)
        if problem.dim == 3:
            self.condensed = self.pdas is not None and self._algebraic_jacobian_3d(J)
        else:
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

    def _friction_forms(self, problem, w, dv):
        """(F, the Jacobian shift's integrand, j_eps(v) - j_eps(v0) integrand) of the regularised
        problem in UFL: the scalar law on v.tau in 2-D, the vector law on v - (v.nu) nu in 3-D."""
        v, g, ds = problem.v, problem.g, problem.nodal_ds()
        if problem.dim == 2:
            tt = problem.tangent()
            v_tau = ufl.dot(v, tt)
            F = ufl.action(problem.a, v) - problem.l + Phi_reg(v_tau, g, self.eps) * ufl.dot(w, tt) * ds
            return (F, self.shift * g * ufl.dot(dv, tt) * ufl.dot(w, tt),
                    F_reg(v_tau, g, self.eps) - F_reg(ufl.dot(self.v0, tt), g, self.eps))
        v_tau = problem.tangential(v)  # 3-D: Phi_eps(v_tau) = g v_tau / max(|v_tau|, eps)
        F = (ufl.action(problem.a, v) - problem.l
             + ufl.dot(Phi_reg_vector(v_tau, g, self.eps), problem.tangential(w)) * ds)
        return (F, self.shift * g * problem.tangential_product(dv, w),
                F_reg_vector(v_tau, g, self.eps)
                - F_reg_vector(problem.tangential(self.v0), g, self.eps))

    def _newton_K(self, x):
        """The Jacobian's diagonal on the free tangential contact dofs at x: m g (1/eps on the
        stick nodes |v_tau/eps| <= 1, as UFL differentiates clip, plus the shift). 3-D: the
        2x2 blocks of law.jacobian_blocks on all contact nodes."""
        eps = float(self.eps.value)
        if self.nodes.dim == 3:
            return law.jacobian_blocks(self.nodes.tangential(x), self.nodes.g * self.nodes.m, eps,
                                       float(self.shift.value))
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

    def _algebraic_jacobian_3d(self, J) -> bool:
        """3-D: the SNES Jacobian is A + blocks(_newton_K(iterate)), assembled into a copy of A
        (condensed.BlockUpdateSolver, re-assembled only when the blocks change); unless it
        differs from the assembled UFL Jacobian. The preconditioning matrix P is a copy of an
        earlier J, refreshed (hence re-factorised) only when the stick set changes, the previous
        linear solve failed or needed more than LAG_MAX_ITS_3D iterations, or the KSP is
        ``preonly`` (then P = J always)."""
        V = self.p.V
        self.blocks = BlockUpdateSolver(self.residual.A, self.pdas.rows, self.pdas.free_rows,
                                        self.prefix + "jacobian_", linear_defaults(V),
                                        near_nullspace(V))
        if not self._jacobian_matches(J):
            return False
        self._P, self._P_key = self.blocks.J.duplicate(copy=True), None
        self.jacobian_refreshes = 0
        if near_nullspace(V) is not None:
            self._P.setNearNullSpace(near_nullspace(V))
        ksp = self.newton.snes.snes.getKSP()

        def jacobian(snes_, x, J_, P_):
            self.blocks.set_K(self._newton_K(x))
            key = self._stick_set(x)[: 2 + self.nodes.dofs.size]  # eps, shift, stick set
            same = self._P_key is not None and np.array_equal(key, self._P_key)
            lag = (ksp.getType() != "preonly" and ksp.getConvergedReason() >= 0
                   and ksp.getIterationNumber() <= LAG_MAX_ITS_3D)
            if not self.p.msh.comm.allreduce(bool(same and lag), op=MPI.LAND):
                self.blocks.J.copy(self._P, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
                self._P_key = key
                self.jacobian_refreshes += 1
        self.newton.snes.snes.setJacobian(jacobian, self.blocks.J, self._P)
        return True

    def _jacobian_matches(self, J, rtol=1e-10) -> bool:
        """True if the assembled UFL Jacobian equals A + diag(_newton_K) (3-D: A + blocks) on
        every rank."""
        v, A = self.p.v, self.residual.A
        form = compat.form(J)
        M = compat.create_matrix(form)
        d = A.createVecLeft()
        rows = np.sort(self.pdas.rows[self.pdas.free_rows])
        saved = v.x.array.copy()
        pattern = test_pattern(self.p.V)
        worst = 0.0
        for scale in (1.0, 2.0 * self.target):
            for shift in (0.0, JACOBIAN_SHIFT):
                v.x.array[:] = scale * pattern
                self.shift.value = shift
                M.zeroEntries()
                compat.assemble_matrix(M, form, self.p.bcs)
                M.assemble()
                size = M.norm(PETSc.NormType.INFINITY)
                if self.nodes.dim == 3:
                    self.blocks.set_K(self._newton_K(compat.petsc_vec(v)))
                    M.axpy(-1.0, self.blocks.J,
                           structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
                    worst = max(worst, M.norm(PETSc.NormType.INFINITY) / max(size, 1e-300))
                    continue
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
        |v_tau| <= eps (nodal quadrature), read from the SNES iterate x. In 3-D also v_tau on the
        sliding nodes (their blocks depend on it)."""
        if self.nodes.dim == 3:
            s = self.nodes.tangential(x)
            stick = law.stick(s, float(self.eps.value))
            return np.concatenate([[float(self.eps.value), float(self.shift.value)], stick,
                                   np.where(stick[:, None], 0.0, s).ravel()])
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
        self.nodes.refresh_bound()  # a bound of the state: evaluated now (nodes.py)
        if self.algebraic and self._a_constants.changed():
            raise ConvergenceError(
                f"the friction problem's operator a holds {self._a_constants.names}, whose value "
                "changed after its solver was built, and this solver keeps the matrix of a from "
                "one solve to the next: give such a datum as a Function (the solver then "
                "assembles a at every iteration) or build the friction solver again")
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
