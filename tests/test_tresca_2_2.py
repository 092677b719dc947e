"""Section 2.2: the three friction solvers solve the same discrete problem, the SNES-VI damage
keeps its bounds, serial = mpirun -n 2, and the stick-slip physics of Example 3."""
import csv

import numpy as np

from conftest import load_run, rel_diff, run_cli, serial_and_two_ranks


def test_three_friction_solvers_agree(tmp_path):
    """Newton on Phi_eps (eps = 1e-9), Uzawa (eps = 0) and penalty-duality give the same fields
    (stopping tests tightened to 1e-10 for the comparison)."""
    base = ["run", "2.2-ex1", "--n", "8", "--k", "0.01", "--T", "0.3", "--no-figures", "--quiet",
            "--set", "friction_tol=1e-10"]
    runs = {}
    for solver in ("newton", "uzawa", "penalty-duality"):
        run_cli(base + ["--set", f"friction_solver={solver}", "--out", tmp_path / solver])
        runs[solver] = load_run(tmp_path / solver)
    _, newton = runs["newton"]
    for solver in ("uzawa", "penalty-duality"):
        summary, fields = runs[solver]
        assert summary["iterations"]["friction_solver"] == solver
        assert rel_diff(fields["u"], newton["u"]) < 1e-6, solver
        assert rel_diff(fields["zeta"], newton["zeta"]) < 1e-6, solver


def test_damage_bounds_and_serial_equals_two_ranks(tmp_path):
    (_, s), _ = serial_and_two_ranks(
        tmp_path, ["run", "2.2-ex1", "--n", "8", "--k", "0.02", "--no-figures", "--quiet"])
    # the obstacle step keeps zeta in [zeta_star, 1] at every dof, and the bound is reached
    assert s["zeta"].min() >= 0.01 - 1e-12 and s["zeta"].max() <= 1 + 1e-12
    assert s["zeta"].min() <= 0.01 + 1e-9
    with open(tmp_path / "s" / "history.csv") as f:
        assert min(float(r["zeta_min"]) for r in csv.DictReader(f)) >= 0.01 - 1e-12


def test_uzawa_is_refused_without_gamma_D(tmp_path):
    proc = run_cli(["run", "2.2-ex3", "--n", "4", "--set", "friction_solver=uzawa", "--quiet",
                    "--out", tmp_path], check=False)
    assert proc.returncode == 2 and "Gamma_D" in proc.stderr


def test_stick_slip_example3(tmp_path):
    """Figure 2.12: no motion at (4, 0) while |sigma_tau| < 45; it slides once the bound is
    reached; the top face (g = 1000) stays stuck."""
    run_cli(["run", "2.2-ex3", "--n", "8", "--k", "0.01", "--T", "2", "--no-figures", "--quiet",
             "--out", tmp_path])
    with open(tmp_path / "history.csv") as f:
        rows = list(csv.DictReader(f))[1:]
    u1 = np.array([float(r["probe_u1"]) for r in rows])
    sig = np.array([float(r["probe_sigma_tau"]) for r in rows])
    stuck = np.abs(sig) < 45 * (1 - 1e-6)
    assert stuck.any() and (~stuck).any(), "both regimes must occur"
    first_slip = np.argmax(~stuck)
    assert np.max(np.abs(u1[:first_slip])) < 1e-8           # no motion before the bound
    assert np.abs(u1[-1]) > 1e3 * max(np.max(np.abs(u1[:first_slip])), 1e-15)
    assert np.all(np.abs(sig) <= 45 * (1 + 1e-6))           # never above the bound
    _, fields = load_run(tmp_path)
    X, u = fields["u_coords"], fields["u"]
    top, bottom = np.isclose(X[:, 1], 4.0), np.isclose(X[:, 1], 0.0)
    print(f"max |u1| top {np.abs(u[top, 0]).max():.3e}, bottom {np.abs(u[bottom, 0]).max():.3e}")
    assert np.abs(u[top, 0]).max() < 1e-6 * np.abs(u[bottom, 0]).max()


def _friction_problem(contact_sides):
    """A clamped-left unit square with Tresca friction (g = 3) on ``contact_sides``."""
    import ufl
    from dolfinx import fem, mesh
    from mpi4py import MPI
    from damage_dolfinx import compat
    from damage_dolfinx.friction import FrictionProblem
    from damage_dolfinx.solvers import SolveContext
    msh = mesh.create_unit_square(MPI.COMM_WORLD, 6, 6)
    msh.topology.create_connectivity(1, 2)
    sides = {"left": lambda x: np.isclose(x[0], 0.0), "bottom": lambda x: np.isclose(x[1], 0.0),
             "right": lambda x: np.isclose(x[0], 1.0)}
    facets = {s: mesh.locate_entities_boundary(msh, 1, sides[s]) for s in ("left", *contact_sides)}
    indices = np.concatenate([facets[s] for s in contact_sides])
    order = np.argsort(indices)
    tags = mesh.meshtags(msh, 1, indices[order], np.full(indices.size, 2, dtype=np.int32))
    V = compat.vector_p1(msh)
    u, w = ufl.TrialFunction(V), ufl.TestFunction(V)
    e = lambda f: ufl.sym(ufl.grad(f))  # noqa: E731
    a = ufl.inner(e(u), e(w)) * ufl.dx
    l = ufl.dot(fem.Constant(msh, np.array([5.0, -1.0])), w) * ufl.dx
    clamp = fem.dirichletbc(np.zeros(2), fem.locate_dofs_topological(V, 1, facets["left"]), V)
    ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
    return FrictionProblem(fem.Function(V), a, l, [clamp], fem.Constant(msh, 3.0), ds(2),
                           SolveContext("unit"))


def test_algebraic_friction_residual():
    """The Newton residual A v - b + sum_i m_i Phi_eps(v_tau,i) tau_i (no assembly) equals the
    assembled UFL residual on a straight Gamma_C, so both give the same velocity; on a bent
    Gamma_C (a corner node) it does not, and the solver falls back to assembly."""
    from damage_dolfinx.friction import RegularisedNewton
    velocities = []
    for force_assembly in (False, True):
        newton = RegularisedNewton(_friction_problem(("bottom",)), eps_reg=1e-9)
        assert newton.algebraic
        if force_assembly:
            newton.use_form_residual()
        newton.solve()
        velocities.append(newton.p.v.x.array.copy())
    assert np.linalg.norm(velocities[0] - velocities[1]) <= 1e-9 * np.linalg.norm(velocities[1])
    assert np.abs(velocities[1]).max() > 1e-3  # it moves (and slides)
    bent = RegularisedNewton(_friction_problem(("bottom", "right")), eps_reg=1e-9)
    assert not bent.algebraic
    bent.solve()
