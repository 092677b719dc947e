"""Second-kind variational inequalities with Tresca friction (velocity step (2.67), increment
step (2.187), dynamic step (3.94)): interchangeable solvers of the same discrete problem

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
The reproduction adds two baselines (``reproduction/baselines.py``, registered with
:func:`register_solver` when imported; not part of the installed library):

* ``Uzawa`` (2.98) with two misprints corrected (docs/models.md, section 2.2):
  lambda_{s+1} = P(lambda_s + rho g v_tau),
  P(x) = x / max(1, |x|); the unregularised problem (needs Gamma_D: a must be coercive).
* ``PenaltyDuality``: the Bermudez-Moreno iteration on the regularised problem, as in the
  thesis: Phi_eps(v_tau) = omega v_tau + q, q_{s+1} = (G - omega I)_lambda(v_tau + lambda q_s),
  lambda omega = 1/2.

Uzawa and penalty-duality factorise their constant matrix once and update nodal multipliers
with NumPy (no loops over dofs); both stop when ||v_{s+1} - v_s||_V <= tol ||v_{s+1}||_V
(thesis: tol = 1e-6).

3-D: the same four iterations with a 2-D tangent plane, w_tau a 2-vector per node
(two coordinate-axis tangents; Gamma_C made of faces parallel to coordinate planes, others are
refused), |w_tau| its Euclidean norm: Phi_eps(s) = g s / max(|s|, eps) (in 2-D this is
g max(-1, min(1, s/eps)), (2.99)), Newton's Jacobian blocks m g/eps I (stick) and
m g/|s| (I - s s^T/|s|^2) (slip), 2-vector multipliers in the active-set iteration, Uzawa's
projection onto the disc of radius 1, penalty-duality's resolvent along s/|s| (``law``).
The 2-D code paths are unchanged (2-D results identical bit for bit).

Modules: ``nodes`` (FrictionProblem, ContactNodes), ``law`` (the nodal law in NumPy),
``residual`` (AlgebraicResidual), ``active_set`` (PrimalDualActiveSet), ``newton``
(RegularisedNewton); here the selection by parameters (:data:`SOLVERS`, :func:`register_solver`).
"""
from __future__ import annotations

import numpy as np

from damage_dolfinx.core.parameters import InputError
from damage_dolfinx.numerics.friction import law
from damage_dolfinx.numerics.friction.active_set import PrimalDualActiveSet
from damage_dolfinx.numerics.friction.newton import (FAST_MAX_IT, FAST_PAUSE_STEPS, FRICTION_NEWTON, PDAS_MAX_IT, REFACTOR_ITS,
                     RegularisedNewton)
from damage_dolfinx.numerics.friction.nodes import JACOBIAN_SHIFT, ContactNodes, FrictionProblem
from damage_dolfinx.numerics.friction.residual import AlgebraicResidual

__all__ = ["law", "AlgebraicResidual", "ContactNodes", "FAST_MAX_IT",
           "FAST_PAUSE_STEPS", "FRICTION_NEWTON", "FrictionProblem", "JACOBIAN_SHIFT",
           "PDAS_MAX_IT", "PrimalDualActiveSet", "REFACTOR_ITS",
           "RegularisedNewton", "SOLVERS", "iteration_counters", "make_solver",
           "register_solver", "solver_from_parameters"]


def _newton(problem, eps_reg, rho_uzawa, omega_pd, tol):
    return RegularisedNewton(problem, eps_reg)


_newton.assembles_operator_of_state = True  # an operator a of the state: see RegularisedNewton


#: the friction solvers by name: factory(problem, eps_reg, rho_uzawa, omega_pd, tol); Newton on
#: the regularised law is the library's; others are registered (the reproduction's baselines)
SOLVERS = {"newton": _newton}
#: solvers that need a clamped part Gamma_D
_NEEDS_CLAMP = set()


def register_solver(name: str, factory, needs_clamp: bool = False):
    """Make ``factory(problem, eps_reg, rho_uzawa, omega_pd, tol)`` the friction solver
    ``name`` (the parameter ``friction_solver``); ``needs_clamp``: refused without Gamma_D. A
    problem whose operator a holds Functions is refused for it unless the factory has the
    attribute ``assembles_operator_of_state = True`` (it then assembles a where a can have
    changed)."""
    SOLVERS[name] = factory
    if needs_clamp:
        _NEEDS_CLAMP.add(name)

#: Uzawa step (the thesis gives none) from log-spaced sweeps at n = 16, k = 0.01 (all nodes slip)
#: and k = 0.02 (stick-slip): the largest rho that converges in both (the iteration counts:
#: benchmarks/README.md, "Why the defaults")
RHO_UZAWA = 1.0
#: Bermudez-Moreno omega from the same sweep: the one closest to Newton's solution at tol 1e-6
#: at a moderate iteration count (benchmarks/README.md, "Why the defaults")
OMEGA_PD = 100.0

#: the friction data every friction model's defaults hold (``params.extra``)
FRICTION_DEFAULTS = {"eps_reg": 1e-9, "friction_solver": "newton", "rho_uzawa": RHO_UZAWA,
                     "omega_pd": OMEGA_PD, "friction_tol": 1e-6}

#: the rules of the friction data (a friction model's ``rules`` include them)
FRICTION_RULES = {
    "g_fric": (lambda v: v >= 0, "(friction bound) must be >= 0"),
    "eps_reg": (lambda v: v > 0, "(friction regularisation) must be positive"),
    "mu_f": (lambda v: v >= 0, "(friction coefficient) must be >= 0"),
    "friction_solver": (lambda v: v in ("newton", "uzawa", "penalty-duality"),
                        "must be one of newton, uzawa, penalty-duality"),
    "rho_uzawa": (lambda v: v > 0, "(Uzawa step) must be positive"),
    "omega_pd": (lambda v: v > 0, "(penalty-duality parameter) must be positive"),
    "friction_tol": (lambda v: 0 < v < 1, "(relative V-change stopping test) must lie in (0, 1)"),
}


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
    if kind in _NEEDS_CLAMP and comm.allreduce(int(np.sum(facet_tags.values == gamma_D))) == 0:
        others = ", ".join(sorted(set(SOLVERS) - _NEEDS_CLAMP))
        raise InputError(f"{example_id}: the {kind} friction solver needs a clamped part Gamma_D "
                         "(without it its operator is singular or its ||eps(v)|| stopping test "
                         f"cannot see rigid motions); use {others}")
    return make_solver(kind, problem, extra["eps_reg"], extra.get("rho_uzawa", 1.0),
                       extra.get("omega_pd", 100.0), extra.get("friction_tol", 1e-6))


def make_solver(kind: str, problem: FrictionProblem, eps_reg: float, rho_uzawa: float,
                omega_pd: float, tol: float = 1e-6):
    """The friction solver registered as ``kind`` (newton, and those of register_solver)."""
    if kind not in SOLVERS:
        raise InputError(f"unknown friction solver {kind!r}; choose one of {', '.join(SOLVERS)}"
                         " (the reproduction's uzawa and penalty-duality are registered by "
                         "importing reproduction.baselines from the checkout)")
    from damage_dolfinx.numerics.held_data import held
    functions, _ = held(problem.a)
    if functions and not getattr(SOLVERS[kind], "assembles_operator_of_state", False):
        raise InputError(f"the {kind} friction solver keeps the matrix of the operator a from one "
                         "solve to the next, and a holds the Function(s) "
                         f"{', '.join(sorted({f.name for f in functions}))}: it would stay at "
                         "their values when the solver was built; use the newton solver")
    solver = SOLVERS[kind](problem, eps_reg, rho_uzawa, omega_pd, tol)
    nodes = getattr(solver, "nodes", None)
    if hasattr(nodes, "refresh_bound") and not getattr(solver, "refreshes_bound", False):
        solve = solver.solve

        def solve_with_current_bound(*args, **kwargs):  # a bound of the state: evaluated now
            nodes.refresh_bound()
            return solve(*args, **kwargs)
        solver.solve = solve_with_current_bound
    elif nodes is None:
        if held(problem.g)[0]:
            raise InputError(f"the {kind} friction solver cannot evaluate a friction bound that "
                             "depends on the state (it holds no contact nodes to update): use "
                             "the newton solver")
    return solver
