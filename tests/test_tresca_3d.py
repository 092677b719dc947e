"""3-D Tresca friction with a 2-D tangent plane: a block sliding or sticking on its
bottom face under a uniform shear whose direction d = (3, 4, 0)/5 has both tangential components
matches the closed-form simple shear for the four solvers (regularised Newton, the primal-dual
active set, Uzawa, penalty-duality); the same on 2 ranks; non-plane contact faces are refused."""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import ENV

HERE = Path(__file__).parent
D = np.array([3.0, 4.0, 0.0]) / 5.0  # the shear direction, in the bottom plane
MU, LAM, G, H = 2.0, 1.0, 3.0, 1.0


def _block(top_velocity, side_shear, contact="bottom"):
    """Block (0,2)x(0,1.5)x(0,H), viscous operator 2 mu eps : eps + lam div div, bilateral
    contact (v_3 = 0) with Tresca friction (bound G) on the bottom, velocity top_velocity d on the
    top, and the side tractions of the simple shear sigma = side_shear (d e_3^T + e_3 d^T)."""
    import ufl
    from dolfinx import fem, mesh
    from mpi4py import MPI
    from damage_dolfinx import compat
    from damage_dolfinx.numerics.friction import FrictionProblem
    from damage_dolfinx.numerics.solvers import SolveContext
    msh = mesh.create_box(MPI.COMM_WORLD, [np.zeros(3), np.array([2.0, 1.5, H])], [4, 3, 2])
    msh.topology.create_connectivity(2, 3)
    where = {1: lambda x: np.isclose(x[2], 0.0), 2: lambda x: np.isclose(x[2], H),
             3: lambda x: np.isclose(x[0], 0.0), 4: lambda x: np.isclose(x[0], 2.0),
             5: lambda x: np.isclose(x[1], 0.0), 6: lambda x: np.isclose(x[1], 1.5)}
    facets = {t: mesh.locate_entities_boundary(msh, 2, f) for t, f in where.items()}
    indices = np.concatenate(list(facets.values()))
    values = np.concatenate([np.full(f.size, t, dtype=np.int32) for t, f in facets.items()])
    indices, first = np.unique(indices, return_index=True)
    tags = mesh.meshtags(msh, 2, indices, values[first])
    V = compat.vector_p1(msh)
    u, w = ufl.TrialFunction(V), ufl.TestFunction(V)
    e = lambda f: ufl.sym(ufl.grad(f))  # noqa: E731
    a = 2 * MU * ufl.inner(e(u), e(w)) * ufl.dx + LAM * ufl.div(u) * ufl.div(w) * ufl.dx
    ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
    # sigma n on the sides: n = +-e_1 gives +-side_shear d_1 e_3, n = +-e_2 +-side_shear d_2 e_3
    l = side_shear * (D[0] * (w[2] * ds(4) - w[2] * ds(3)) + D[1] * (w[2] * ds(6) - w[2] * ds(5)))
    bottom_v3 = fem.locate_dofs_topological(V.sub(2), 2, facets[1])
    bcs = [fem.dirichletbc(0.0, bottom_v3, V.sub(2))]
    top = fem.locate_dofs_topological(V, 2, facets[2])
    bcs.append(fem.dirichletbc(top_velocity * D, top, V))
    contact_tag = {"bottom": 1, "bottom and side": (1, 3)}[contact]
    return FrictionProblem(fem.Function(V), a, l, bcs, fem.Constant(msh, G), ds(contact_tag),
                           SolveContext("3-D shear block"))


def _cases(eps):
    """(name, top velocity, bottom velocity v_b, shear stress s) of the closed form
    v = (v_b + s x_3/mu) d. Stick: top velocity 0.5 G H/mu, s = mu (V - v_b)/H < G, and the
    regularised law g v_b/eps = s gives v_b = eps s/G (0 for Uzawa, eps = 0). Slip: top velocity
    2.5 > G H/mu = 1.5, the bottom slides along d at v_b = 2.5 - 1.5 = 1 under the stress G."""
    top = 0.5 * G * H / MU
    s = MU * top / (H + eps * MU / G)
    return [("stick", top, eps * s / G, s), ("slip", 2.5, 2.5 - G * H / MU, G)]


def _check(problem, v_b, s, tol, label):
    problem.v.x.scatter_forward()
    X = problem.V.tabulate_dof_coordinates()
    v = problem.v.x.array.reshape(-1, 3)
    exact = (v_b + s * X[:, 2] / MU)[:, None] * D[None, :]
    error = np.abs(v - exact).max() if v.size else 0.0
    print(label, f"max |v - exact| / max |exact| = {error / np.abs(exact).max():.1e}")
    assert error <= tol * np.abs(exact).max() + 1e-14, (label, error)
    # the bottom slides parallel to the shear (both tangential components; in the stick case
    # v_b ~ 1e-9 and its direction is resolved to tol * max|v| / v_b only)
    bottom = np.isclose(X[:, 2], 0.0)
    if bottom.any() and v_b > 0:
        direction = v[bottom, :2] / np.linalg.norm(v[bottom, :2], axis=1)[:, None]
        resolved = tol * np.abs(exact).max() / v_b
        assert np.abs(direction - D[:2]).max() <= 10 * resolved, (label, resolved)


@pytest.mark.parametrize("kind", ["newton", "uzawa", "penalty-duality"])
def test_sliding_block_closed_form(kind):
    """Newton on Phi_eps (eps = 1e-9), Uzawa (eps = 0) and penalty-duality (eps = 1e-9) on the
    3-D stick and slip cases: the P1 solution is the closed-form simple shear."""
    from damage_dolfinx.numerics.friction import make_solver
    eps = 1e-9
    for name, top, v_b, s in _cases(0.0 if kind == "uzawa" else eps):
        problem = _block(top, s)
        solver = make_solver(kind, problem, eps_reg=eps, rho_uzawa=0.1, omega_pd=10.0, tol=1e-12)
        solver.solve()
        tol = 1e-8 if kind == "newton" else 1e-6  # Uzawa, PD: iterative, stopped at 1e-12
        _check(problem, v_b, s, tol, (name, kind))
        if kind == "newton":  # the algebraic residual and the 2x2-block Jacobian are in use
            assert solver.algebraic and solver.condensed, name


def test_primal_dual_active_set_3d_from_a_reversed_start():
    """The primal-dual active-set iteration alone, with 2-vector multipliers, started from a
    velocity sliding against the shear (v = -d), reaches both closed forms."""
    from dolfinx import fem
    from damage_dolfinx import compat
    from damage_dolfinx.numerics.friction import AlgebraicResidual, ContactNodes, PrimalDualActiveSet
    eps = 1e-9
    for name, top, v_b, s in _cases(eps):
        problem = _block(top, s)
        eps_c = fem.Constant(problem.msh, eps)
        residual = AlgebraicResidual(problem, ContactNodes(problem), eps_c)
        residual.assemble_rhs()
        pdas = PrimalDualActiveSet(residual, f"test_pdas3d_{name}_")
        problem.v.x.array.reshape(-1, 3)[:] = -D
        x = compat.petsc_vec(problem.v)
        its = pdas.solve(x, eps, rtol=1e-12, atol=1e-13, max_it=50)
        print(name, its, "iterations")
        _check(problem, v_b, s, 1e-8, (name, "pdas"))
        assert its <= 25, (name, its)


def test_edge_between_contact_faces_is_refused():
    """Tresca on two faces meeting at an edge: the edge nodes have no coordinate-plane tangent
    plane; refused with one clear InputError before any solve."""
    from damage_dolfinx.numerics.friction import make_solver
    from damage_dolfinx.core.parameters import InputError
    with pytest.raises(InputError, match="coordinate plane"):
        make_solver("newton", _block(1.0, 1.0, contact="bottom and side"), eps_reg=1e-9,
                    rho_uzawa=0.1, omega_pd=10.0)


@pytest.mark.mpi
def test_closed_forms_on_two_ranks():
    """The closed-form checks, the refusal and the 2.4 stepper under mpirun -n 2 (the mesh
    split between the ranks)."""
    if _comm_size() > 1:
        pytest.skip("already under MPI")
    cmd = ["mpirun", "-n", "2", sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
           "-m", "not mpi", "-k", "closed_form or reversed_start or refused or viscoplastic",
           str(HERE / "test_tresca_3d.py")]
    proc = subprocess.run(cmd, env=ENV, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout + proc.stderr


def _comm_size():
    from mpi4py import MPI
    return MPI.COMM_WORLD.size


def test_three_friction_solvers_agree_3d(tmp_path):
    """2.2-ex1-3d (n = 4, 20 steps): Newton on Phi_eps (eps = 1e-9), Uzawa (eps = 0) and
    penalty-duality give the same fields (stopping tests tightened to 1e-10)."""
    from conftest import load_run, rel_diff, run_cli
    base = ["run", "2.2-ex1-3d", "--n", "4", "--T", "0.2", "--no-figures", "--quiet",
            "--set", "friction_tol=1e-10"]
    runs = {}
    for solver in ("newton", "uzawa", "penalty-duality"):
        run_cli(base + ["--set", f"friction_solver={solver}", "--out", tmp_path / solver])
        runs[solver] = load_run(tmp_path / solver)
    _, newton = runs["newton"]
    for solver in ("uzawa", "penalty-duality"):
        summary, fields = runs[solver]
        assert summary["iterations"]["friction_solver"] == solver
        print(solver, rel_diff(fields["u"], newton["u"]), rel_diff(fields["zeta"], newton["zeta"]))
        assert rel_diff(fields["u"], newton["u"]) < 1e-6, solver  # measured 2.0e-10, 9.5e-13
        assert rel_diff(fields["zeta"], newton["zeta"]) < 1e-6, solver


def test_viscoplastic_stepper_takes_the_dimension_from_the_mesh():
    """Section 2.4's stepper on the unit cube (2.4-ex1's data, Tresca on y = 0, 5 steps): the
    increment VI is solved (the primal-dual active set with 2-vector multipliers takes the
    steps where full Newton steps fail) and Gamma_C slides."""
    import dataclasses
    import ufl
    from mpi4py import MPI
    from damage_dolfinx.catalogue import examples
    from damage_dolfinx.catalogue.section_3d_tresca import _unit_cube
    ex = dataclasses.replace(
        examples.get("2.4-ex1", "literal"), dim=3, mesh=_unit_cube, literal=None,
        readings={}, reading=None,
        traction=lambda x, t: ufl.as_vector((50.0 * (ufl.exp(t) - 1.0), 0.0, 0.0)))
    s = ex.build(MPI.COMM_WORLD, n=4, k=0.02)
    s.initialize()
    for _ in range(5):
        s.advance()
    scalars, its = s.scalars(), s.iteration_totals()
    print(scalars, its)
    assert scalars["slip_max"] > 1e-3 and scalars["zeta_min"] < 1.0
    assert its["friction_pdas_failures"] == 0 and its["friction_continuations"] == 0


@pytest.mark.mpi
@pytest.mark.parametrize("example", ["2.2-ex1-3d", "3.2-ex1-3d"])
def test_3d_tresca_examples_serial_equal_two_ranks(tmp_path, example):
    """The 3-D Tresca examples at n = 4 (10 steps, the body slides on its bottom face) give the
    same final fields on 1 and 2 ranks to solver tolerance, with the figure and the XDMF."""
    from conftest import serial_and_two_ranks
    (s_sum, s_fields), (p_sum, _) = serial_and_two_ranks(
        tmp_path, ["run", example, "--n", "4", "--T", "0.1", "--quiet"],
        fields=("u", "v", "zeta", "von_mises"), tol=1e-7)
    # Gamma_C = {y = 0}: v_2 = 0 there, and the face slides along x (the load) and z (the
    # Poisson contraction of the free faces z = 0, 1): both tangential components, far above eps
    bottom = np.isclose(s_fields["v_coords"][:, 1], 0.0)
    v_bottom = np.abs(s_fields["v"][bottom])
    print("max |v| on Gamma_C (x, y, z):", v_bottom.max(axis=0))
    assert v_bottom[:, 1].max() == 0.0 and v_bottom[:, 0].max() > 1e-3
    assert v_bottom[:, 2].max() > 1e-4
    assert s_sum["status"] == "completed" and s_sum["steps_done"] == 10
    assert s_sum["iterations"]["friction_solver"] == "newton"
    for run in ("s", "p"):
        assert (tmp_path / run / "fields_slices.png").exists()
        assert (tmp_path / run / "fields.xdmf").exists()
    for key, value in s_sum["final"].items():
        assert p_sum["final"][key] == pytest.approx(value, rel=1e-7, abs=1e-12), key
