"""Data of the state in the building blocks' operators: a matrix kept from one solve to the next
(a constant matrix, a product taken out of the right-hand side, the damage step's operator, the
friction problem's operator a) is assembled again when a Function or Constant in it has changed,
or refused where it cannot be; never held at its value when the solver was built. Each case
compares a datum changed after the solver was built with a solver built on the changed datum."""
import runpy
from pathlib import Path

import numpy as np
import pytest
import ufl
from dolfinx import fem
from mpi4py import MPI

import damage_dolfinx as dd
from damage_dolfinx import blocks as b

DEMO = runpy.run_path(str(Path(__file__).resolve().parent.parent / "demos" /
                          "demo_coulomb_friction.py"), run_name="demo_coulomb_friction")


def _block(n=2):
    geometry = DEMO["block"](MPI.COMM_WORLD, n)
    ds = ufl.Measure("ds", domain=geometry.mesh, subdomain_data=geometry.facet_tags)
    return geometry.mesh, ds


def _scalar_problem(msh, c):
    Z = b.scalar_p1(msh)
    u, w = ufl.TrialFunction(Z), ufl.TestFunction(Z)
    x = ufl.SpatialCoordinate(msh)
    return Z, (1 + c) * u * w * ufl.dx + ufl.inner(ufl.grad(u), ufl.grad(w)) * ufl.dx, \
        (1 + x[0]) * w * ufl.dx


@pytest.mark.parametrize("datum", ["function", "constant"])
def test_a_constant_matrix_follows_its_data(datum):
    msh, _ = _block()
    Z = b.scalar_p1(msh)
    c = fem.Function(Z, name="c") if datum == "function" else fem.Constant(msh, 0.0)
    Z, a, L = _scalar_problem(msh, c)
    solver = b.LinearSolver(a, L, [], "test_", b.SolveContext(), constant_matrix=True)
    first, again = fem.Function(Z), fem.Function(Z)
    solver.solve(first)
    if datum == "function":
        c.x.array[:] = 3.0
    else:
        c.value = 3.0
    solver.solve(again)
    fresh = fem.Function(Z)
    b.LinearSolver(a, L, [], "fresh_", b.SolveContext()).solve(fresh)
    assert np.abs(again.x.array - fresh.x.array).max() < 1e-12
    assert np.abs(first.x.array - fresh.x.array).max() > 1e-3  # the datum mattered


def test_a_product_out_of_the_right_hand_side_follows_its_data():
    msh, _ = _block()
    Z = b.scalar_p1(msh)
    u, w = ufl.TrialFunction(Z), ufl.TestFunction(Z)
    rho, f = fem.Constant(msh, 1.0), fem.Function(Z)
    f.x.array[:] = 1.0
    a = u * w * ufl.dx + ufl.inner(ufl.grad(u), ufl.grad(w)) * ufl.dx
    solver = b.LinearSolver(a, fem.Constant(msh, 0.0) * w * ufl.dx, [], "test_", b.SolveContext(), constant_matrix=True,
                            rhs_product=(rho * u * w * ufl.dx, f))
    out = fem.Function(Z)
    rho.value = 2.0
    solver.solve(out)
    reference = fem.Function(Z)
    b.LinearSolver(a, 2.0 * f * w * ufl.dx, [], "fresh_", b.SolveContext()).solve(reference)
    assert np.abs(out.x.array - reference.x.array).max() < 1e-12


def test_the_damage_step_follows_a_kappa_of_the_state():
    msh, _ = _block()
    Z = b.scalar_p1(msh)
    kappa = fem.Function(Z, name="kappa")
    x = ufl.SpatialCoordinate(msh)

    def step(kappa_value):
        zeta, zeta_old = fem.Function(Z), fem.Function(Z)
        zeta_old.interpolate(lambda p: 0.5 + 0.4 * np.sin(3 * p[0]))
        return zeta, dd.blocks.DamageStep(zeta, zeta_old, -(1 + x[0]), 0.1, kappa_value,
                                          b.SolveContext(), obstacle=True)
    zeta, damage = step(kappa)
    damage.solve()
    kappa.x.array[:] = 5.0
    damage.solve()
    zeta_fresh, fresh = step(fem.Constant(msh, 5.0))
    fresh.solve()
    assert np.abs(zeta.x.array - zeta_fresh.x.array).max() < 1e-9


def _friction_problem(msh, ds, c):
    V = b.vector_p1(msh)
    v = fem.Function(V, name="v")
    dv, w = ufl.TrialFunction(V), ufl.TestFunction(V)
    a = ufl.dot(dv, w) * ufl.dx + ufl.inner(b.eps(dv), b.eps(w)) * ufl.dx \
        + c * ufl.dot(dv, w) * ds(3)
    l = ufl.dot(ufl.as_vector((1.0, 0.0)), w) * ufl.dx
    return v, b.FrictionProblem(v, a, l, [], fem.Constant(msh, 0.1), ds(3), b.SolveContext())


def test_a_friction_operator_of_the_state_is_assembled_where_it_changes():
    msh, ds = _block()
    c = fem.Function(b.scalar_p1(msh), name="c")
    v, problem = _friction_problem(msh, ds, c)
    solver = b.friction_solver("newton", problem, 1e-9, 1.0, 100.0)
    solver.solve()
    before = v.x.array.copy()
    c.x.array[:] = 50.0
    solver.solve()
    v_fresh, fresh_problem = _friction_problem(msh, ds, fem.Constant(msh, 50.0))
    b.friction_solver("newton", fresh_problem, 1e-9, 1.0, 100.0).solve()
    assert np.abs(v.x.array - v_fresh.x.array).max() < 1e-9
    assert np.abs(before - v_fresh.x.array).max() > 1e-2  # the stiffness mattered


def test_a_changed_constant_of_a_kept_friction_operator_stops_the_solve():
    msh, ds = _block()
    c = fem.Constant(msh, 0.0)
    v, problem = _friction_problem(msh, ds, c)
    solver = b.friction_solver("newton", problem, 1e-9, 1.0, 100.0)
    solver.solve()
    c.value = 50.0
    with pytest.raises(dd.ConvergenceError, match="changed after its solver was built"):
        solver.solve()


def test_a_friction_solver_that_keeps_its_operator_refuses_one_of_the_state():
    from damage_dolfinx.numerics import friction
    msh, ds = _block()
    c = fem.Function(b.scalar_p1(msh), name="c")
    v, problem = _friction_problem(msh, ds, c)
    friction.register_solver("keeps-a", lambda *args: pytest.fail("built"))
    try:
        with pytest.raises(dd.InputError, match="holds the Function.*c.*use the newton"):
            b.friction_solver("keeps-a", problem, 1e-9, 1.0, 100.0)
    finally:
        del friction.SOLVERS["keeps-a"]


@pytest.mark.parametrize("given, message", [
    (dict(rho=0.0), "rho must be > 0"), (dict(rho=-1.0), "rho must be > 0"),
    (dict(E=-1.0), "E must be > 0"), (dict(nu=0.6), "nu must be < 0.5"),
    (dict(m_visc=0.0), "m_visc must be > 0"), (dict(E=float("nan")), "E must be a finite"),
    (dict(c_nu=-5.0), "c_nu must be >= 0"),
])
def test_a_stability_estimate_of_impossible_data_is_refused(given, message):
    # were a PETSc error code, a ZeroDivisionError, a C compile error (E = nan) or a number
    msh, _ = _block()
    data = {"E": 1.0, "nu": 0.3, "rho": 1.0, "m_visc": 1.0, **given}
    with pytest.raises(dd.InputError, match=message):
        b.estimate_k_max(b.vector_p1(msh), **data)
