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
    # the literal load (100, 0)e^t drives zeta to its bound zeta_star (the evidence reading
    # (e^t - 1) keeps zeta_min ~ 0.6, benchmarks/readings.md)
    (_, s), _ = serial_and_two_ranks(
        tmp_path, ["run", "2.2-ex1", "--n", "8", "--k", "0.02", "--no-figures", "--quiet",
                   "--reading", "literal"])
    # the obstacle step keeps zeta in [zeta_star, 1] at every dof, and the bound is reached
    assert s["zeta"].min() >= 0.01 - 1e-12 and s["zeta"].max() <= 1 + 1e-12
    assert s["zeta"].min() <= 0.01 + 1e-9
    with open(tmp_path / "s" / "history.csv") as f:
        serial = list(csv.DictReader(f))
    assert min(float(r["zeta_min"]) for r in serial) >= 0.01 - 1e-12
    # the contact forces (assembled over the cells that touch Gamma_C, ghost cells included)
    # are the same on 2 ranks
    with open(tmp_path / "p" / "history.csv") as f:
        parallel = list(csv.DictReader(f))
    for column in ("contact_normal_force", "contact_force_x", "contact_force_y",
                   "friction_force"):
        a = np.array([float(r[column]) for r in serial])
        b = np.array([float(r[column]) for r in parallel])
        assert np.abs(a - b).max() <= 1e-7 * np.abs(a).max(), column


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
    from damage_dolfinx.numerics.friction import FrictionProblem
    from damage_dolfinx.numerics.solvers import SolveContext
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
    from damage_dolfinx.numerics.friction import RegularisedNewton
    velocities = []
    for force_assembly in (False, True):
        newton = RegularisedNewton(_friction_problem(("bottom",)), eps_reg=1e-9)
        assert newton.algebraic
        if force_assembly:
            newton.use_form_residual()
        newton.solve()
        velocities.append(newton.p.v.x.array.copy())
    assert np.linalg.norm(velocities[0] - velocities[1]) <= 1e-9 * np.linalg.norm(velocities[1])
    # the algebraic line-search energy E(x) - E(v0) equals the assembled one (on V)
    from damage_dolfinx import compat
    x = compat.petsc_vec(newton.p.v).copy()
    newton.v0.x.array[:] = 0.5 * newton.p.v.x.array
    for scale in (1.0, 1e-9):  # slip and near the stick threshold
        x.array[:] = scale * np.sin(np.arange(x.array.size))
        compat.set_bc(x, newton.p.bcs)  # Newton iterates satisfy the Dirichlet conditions
        newton.algebraic = True
        algebraic = newton._objective(None, x)
        newton.algebraic = False
        assembled = newton._objective(None, x)
        assert abs(algebraic - assembled) <= 1e-10 * abs(assembled), (scale, algebraic, assembled)
    assert np.abs(velocities[1]).max() > 1e-3  # it moves (and slides)
    bent = RegularisedNewton(_friction_problem(("bottom", "right")), eps_reg=1e-9)
    assert not bent.algebraic
    bent.solve()


def _shear_block(mu, lam, g, side_shear, top_shear=None, top_velocity=None):
    """Block (0,2)x(0,1), viscous operator 2 mu eps : eps + lam div div, bilateral contact with
    Tresca friction (bound g) on the bottom, shear tractions (0, +-side_shear) on the sides and
    either a shear traction (top_shear, 0) or a velocity (top_velocity, 0) on the top."""
    import ufl
    from dolfinx import fem, mesh
    from mpi4py import MPI
    from damage_dolfinx import compat
    from damage_dolfinx.numerics.friction import FrictionProblem
    from damage_dolfinx.numerics.solvers import SolveContext
    msh = mesh.create_rectangle(MPI.COMM_WORLD, [np.zeros(2), np.array([2.0, 1.0])], [8, 4])
    msh.topology.create_connectivity(1, 2)
    where = {1: lambda x: np.isclose(x[1], 0.0), 2: lambda x: np.isclose(x[1], 1.0),
             3: lambda x: np.isclose(x[0], 0.0), 4: lambda x: np.isclose(x[0], 2.0)}
    facets = {t: mesh.locate_entities_boundary(msh, 1, f) for t, f in where.items()}
    indices = np.concatenate(list(facets.values()))
    values = np.concatenate([np.full(f.size, t, dtype=np.int32) for t, f in facets.items()])
    indices, first = np.unique(indices, return_index=True)
    tags = mesh.meshtags(msh, 1, indices, values[first])
    V = compat.vector_p1(msh)
    u, w = ufl.TrialFunction(V), ufl.TestFunction(V)
    e = lambda f: ufl.sym(ufl.grad(f))  # noqa: E731
    a = 2 * mu * ufl.inner(e(u), e(w)) * ufl.dx + lam * ufl.div(u) * ufl.div(w) * ufl.dx
    ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
    l = side_shear * (w[1] * ds(4) - w[1] * ds(3))
    bottom_v2 = fem.locate_dofs_topological(V.sub(1), 1, facets[1])
    bcs = [fem.dirichletbc(0.0, bottom_v2, V.sub(1))]
    if top_velocity is None:
        l = l + top_shear * w[0] * ds(2)
    else:
        top = fem.locate_dofs_topological(V, 1, facets[2])
        bcs.append(fem.dirichletbc(np.array([top_velocity, 0.0]), top, V))
    return FrictionProblem(fem.Function(V), a, l, bcs, fem.Constant(msh, g), ds(1),
                           SolveContext("shear block"))


def test_friction_solvers_reproduce_simple_shear():
    """Closed-form simple shear v = (v_b + sigma_12 y / mu, 0) (P1 represents it exactly).
    Stick: shear stress s = 1 < g = 3, the regularised law gives v_b = eps s / g. Slip: top
    velocity 2.5 > g H / mu = 1.5, the bottom slides at v_b = 2.5 - 1.5 = 1 under the friction
    stress g (the friction force equals g times the contact length). Newton for both; Uzawa and
    penalty-duality for the slip case."""
    from damage_dolfinx.numerics.friction import make_solver
    mu, lam, g, eps = 2.0, 1.0, 3.0, 1e-9
    cases = [("stick", dict(side_shear=1.0, top_shear=1.0), eps * 1.0 / g, 1.0, ["newton"]),
             ("slip", dict(side_shear=g, top_velocity=2.5), 1.0, g,
              ["newton", "uzawa", "penalty-duality"])]
    for name, load, v_b, shear, solvers in cases:
        for kind in solvers:
            problem = _shear_block(mu, lam, g, **load)
            make_solver(kind, problem, eps_reg=eps, rho_uzawa=0.1, omega_pd=10.0,
                        tol=1e-12).solve()
            X = problem.V.tabulate_dof_coordinates()[:, :2]
            v = problem.v.x.array.reshape(-1, 2)
            exact = v_b + shear * X[:, 1] / mu
            tol = 1e-8 if kind == "newton" else 1e-6  # Uzawa, PD: iterative, stopped at 1e-12
            assert np.abs(v[:, 0] - exact).max() <= tol * max(np.abs(exact).max(), 1e-300) \
                + 1e-14, (name, kind, np.abs(v[:, 0] - exact).max())
            assert np.abs(v[:, 1]).max() <= 1e-10, (name, kind)


def test_primal_dual_active_set_from_a_reversed_start():
    """The primal-dual active-set iteration alone (PrimalDualActiveSet), started from a velocity
    sliding the wrong way (v = (-1, 0)), reaches the closed-form stick and slip solutions of the
    simple-shear block to the primal Newton's accuracy."""
    from damage_dolfinx.numerics.friction import ContactNodes, AlgebraicResidual, PrimalDualActiveSet
    from dolfinx import fem
    from damage_dolfinx import compat
    mu, lam, g, eps = 2.0, 1.0, 3.0, 1e-9
    for name, load, v_b, shear in [("stick", dict(side_shear=1.0, top_shear=1.0), eps / g, 1.0),
                                   ("slip", dict(side_shear=g, top_velocity=2.5), 1.0, g)]:
        problem = _shear_block(mu, lam, g, **load)
        residual = AlgebraicResidual(problem, ContactNodes(problem), fem.Constant(problem.msh, eps))
        residual.assemble_rhs()
        pdas = PrimalDualActiveSet(residual, f"test_pdas_{name}_")
        assert pdas.usable
        problem.v.x.array.reshape(-1, 2)[:, 0] = -1.0
        x = compat.petsc_vec(problem.v)
        its = pdas.solve(x, eps, rtol=1e-12, atol=1e-13, max_it=50)
        print(name, its, "iterations")
        problem.v.x.scatter_forward()
        X = problem.V.tabulate_dof_coordinates()[:, :2]
        v = problem.v.x.array.reshape(-1, 2)
        exact = v_b + shear * X[:, 1] / mu
        assert np.abs(v[:, 0] - exact).max() <= 1e-8 * np.abs(exact).max(), (name, its)
        assert its <= 20, (name, its)  # measured: 12 (stick, with the proximal shift), 8 (slip)


def test_primal_dual_active_set_shortens_the_hard_steps():
    """2.2-ex1 at k = 0.02 (the stability limit, where the previous velocity is a poor start):
    the solver chain with the primal-dual active-set attempt gives the same displacement as the
    chain without it (switched off by the PETSc option -friction_pdas_max_it 0), in fewer
    iterations."""
    from mpi4py import MPI
    from petsc4py import PETSc
    from damage_dolfinx.catalogue import examples
    runs, opts = {}, PETSc.Options()
    for with_pdas in (True, False):
        s = examples.get("2.2-ex1", "literal").build(MPI.COMM_WORLD, n=16, k=0.02)
        if not with_pdas:
            opts["friction_pdas_max_it"] = 0
        try:
            s.initialize()
            for _ in range(s.num_steps):
                s.advance()
        finally:
            opts.delValue("friction_pdas_max_it")
        runs[with_pdas] = (s.u.x.array.copy(), s.friction.iterations, s.friction.pdas_solves)
    (u1, its1, pdas1), (u0, its0, pdas0) = runs[True], runs[False]
    assert pdas1 > 0 and pdas0 == 0
    assert np.abs(u1 - u0).max() <= 1e-6 * np.abs(u0).max()
    assert its1 < its0 / 2, (its1, its0)
