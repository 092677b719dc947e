"""Coulomb friction, a bound of the state (blocks.coulomb_friction_bound): evaluated at every
step, never frozen at its value when the solver was built (demos/demo_coulomb_friction.py)."""
import runpy
from pathlib import Path

import pytest

import damage_dolfinx as dd

DEMO = runpy.run_path(str(Path(__file__).resolve().parent.parent / "demos" /
                          "demo_coulomb_friction.py"), run_name="demo_coulomb_friction")


def test_a_bound_of_the_state_follows_the_pressure(tmp_path):
    # no preload: p_nu(u_0) = 0, the bound when the solver is built is 0 (a frozen bound lets the
    # block slide freely, dP/dt = 2); the normal load rises over 0.2: stick once mu q > f_x
    dd.run(DEMO["problem"](2.0, preload=0.0, ramp=0.2, T=0.6), tmp_path / "stick",
           progress=False, figures=False)
    s, N, t, P = DEMO["slope"](tmp_path / "stick")
    assert abs(N - 10.0) < 0.2
    assert abs(s) < 0.05, s


def test_slip_follows_the_momentum_balance(tmp_path):
    dd.run(DEMO["problem"](4.0, T=0.5), tmp_path / "slip", progress=False, figures=False)
    s, N, t, P = DEMO["slope"](tmp_path / "slip")
    assert abs(s - (4.0 - 0.3 * N)) < 2e-2 * 3.0


def test_a_bound_of_the_friction_unknown_is_refused():
    import ufl
    from dolfinx import fem
    from mpi4py import MPI
    from damage_dolfinx import blocks as b
    geometry = DEMO["block"](MPI.COMM_WORLD, 1)
    V = b.vector_p1(geometry.mesh)
    v = fem.Function(V, name="v")
    dv, w = ufl.TrialFunction(V), ufl.TestFunction(V)
    ds = ufl.Measure("ds", domain=geometry.mesh, subdomain_data=geometry.facet_tags)
    nu = ufl.FacetNormal(geometry.mesh)
    problem = b.FrictionProblem(v, ufl.dot(dv, w) * ufl.dx, ufl.dot(ufl.as_vector((1.0, 0.0)), w) * ufl.dx,
                                [], b.coulomb_friction_bound(0.3, v, nu, 1e3), ds(3),
                                b.SolveContext())
    with pytest.raises(dd.InputError, match="depends on the friction unknown 'v'"):
        b.friction_solver("newton", problem, 1e-9, 1.0, 100.0)


def _friction(g_of):
    import ufl
    from dolfinx import fem
    from mpi4py import MPI
    from damage_dolfinx import blocks as b
    geometry = DEMO["block"](MPI.COMM_WORLD, 1)
    V = b.vector_p1(geometry.mesh)
    v = fem.Function(V, name="v")
    dv, w = ufl.TrialFunction(V), ufl.TestFunction(V)
    ds = ufl.Measure("ds", domain=geometry.mesh, subdomain_data=geometry.facet_tags)
    g = g_of(geometry.mesh)
    problem = b.FrictionProblem(v, ufl.dot(dv, w) * ufl.dx + ufl.inner(b.eps(dv), b.eps(w)) * ufl.dx,
                                ufl.dot(ufl.as_vector((1.0, 0.0)), w) * ufl.dx, [], g, ds(3),
                                b.SolveContext())
    return g, b.friction_solver("newton", problem, 1e-9, 1.0, 100.0)


def test_a_bound_of_x_and_fixed_constants_is_evaluated_once():
    from dolfinx import fem
    import ufl
    g, solver = _friction(lambda msh: fem.Constant(msh, 0.5) * (1 + ufl.SpatialCoordinate(msh)[0]))
    solver.solve()
    solver.solve()
    assert solver.nodes.bound_refreshes == 0      # the thesis models' per-step path


def test_a_constant_bound_that_changes_is_evaluated_again():
    from dolfinx import fem
    g, solver = _friction(lambda msh: fem.Constant(msh, 0.5))
    solver.solve()
    assert solver.nodes.bound_refreshes == 0
    g.value = 2.0
    solver.solve()
    assert solver.nodes.bound_refreshes == 1
    assert abs(solver.nodes.g - 2.0).max() < 1e-12


@pytest.mark.parametrize("value, message", [(-1.0, "negative"), (float("nan"), "not finite"),
                                            (float("inf"), "not finite")])
def test_a_bound_that_is_no_friction_bound_is_refused(value, message):
    from dolfinx import fem
    with pytest.raises(dd.InputError, match=f"friction bound g is {message}.*when the friction "
                                            "solver is built"):
        _friction(lambda msh: fem.Constant(msh, value))


def test_a_bound_that_turns_negative_stops_the_solve():
    from dolfinx import fem
    g, solver = _friction(lambda msh: fem.Constant(msh, 0.5))
    solver.solve()
    g.value = -0.5          # e.g. mu p_nu(u) with a negative mu once contact begins
    with pytest.raises(dd.ConvergenceError, match="negative at a contact node at the start"):
        solver.solve()


def test_a_time_step_above_the_models_mesh_limit_is_refused(tmp_path, capsys):
    # a dynamic model of one's own gives its limit through mesh_k_max(); the run compares k with
    # it once the model is built (was: k = 1.6 k_max ran and 'completed')
    k_max = DEMO["problem"](4.0, T=0.05).k_max()
    with pytest.raises(dd.InputError, match="exceeds the stability limit .*mesh_k_max"):
        dd.run(DEMO["problem"](4.0, T=0.1, k=0.05), tmp_path / "big", progress=False,
               figures=False)
    assert 0.05 > k_max
    import dataclasses
    allowed = dataclasses.replace(DEMO["problem"](4.0, T=0.1, k=0.05), allow_unstable=True)
    assert dd.run(allowed, tmp_path / "allowed", progress=False,
                  figures=False)["status"] == "completed"
    assert "WARNING: time step k = 0.05 exceeds the stability limit" in capsys.readouterr().err


def test_a_dynamic_model_without_its_limit_is_refused(tmp_path):
    import planted_models as pm
    with pytest.raises(dd.InputError, match="implement mesh_k_max"):
        dd.run(pm.problem(pm.PLANTED["dynamic_without_limit"]), tmp_path / "none",
               progress=False, figures=False)
