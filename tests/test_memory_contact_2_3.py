"""Section 2.3: normal compliance against a closed-form solution, the three memory evaluations
against each other, serial = mpirun -n 2, and the physics of Examples 2-3."""
import csv

import numpy as np
import pytest
from mpi4py import MPI

from conftest import load_run, rel_diff, run_cli, serial_and_two_ranks
from damage_dolfinx.geometries import GAMMA_C, GAMMA_D
from damage_dolfinx.geometries.rectangle import rectangle, side
from damage_dolfinx.core.parameters import ModelParameters
from damage_dolfinx.problem.problem import Problem
from damage_dolfinx.models.memory_2_3 import ViscoelasticMemoryContact


def pushed_block(c_nu, E=100.0, H=2.0, g0=0.01, n=4):
    """Block (0,1)x(0,H), top clamped, bottom on a foundation that overlaps it by g0 (gap = -g0),
    nu = 0, no damage, no memory: u = (0, alpha (y - H)) with alpha = -c g0 / (E + c H)."""
    params = ModelParameters(E=E, nu=0.0, variant="A", lam_D=0.0, lam_u=0.0, kappa=1.0,
                             stop_at_zeta_star=False,
                             extra={"c_nu": c_nu, "gap": -g0, "memory_kernel": "constant",
                                    "memory_amplitude": 0.0})
    geo = rectangle(MPI.COMM_WORLD, (0, 0), (1, H), n, 2 * n,
                    {GAMMA_D: side(1, H), GAMMA_C: side(1, 0.0)})
    stepper = ViscoelasticMemoryContact(Problem("2.3", geo, 1.0, k=1.0, params=params, name="nc-test"))
    stepper.initialize()
    X = stepper.u.function_space.tabulate_dof_coordinates()
    u = stepper.u.x.array.reshape(-1, 2)
    alpha = -c_nu * g0 / (E + c_nu * H)
    return u, alpha * (X[:, 1] - H), g0 - u[np.isclose(X[:, 1], 0.0), 1]


@pytest.mark.parametrize("c_nu", [1e1, 1e3, 1e6])
def test_normal_compliance_closed_form(c_nu):
    u, u_y_exact, _ = pushed_block(c_nu)
    assert np.max(np.abs(u[:, 0])) < 1e-12
    assert np.max(np.abs(u[:, 1] - u_y_exact)) < 1e-10 * np.max(np.abs(u_y_exact))


def test_penetration_shrinks_as_stiffness_grows():
    E, H, g0 = 100.0, 2.0, 0.01
    pens = []
    for c in (1e1, 1e2, 1e3, 1e4, 1e6):
        _, _, pen = pushed_block(c, E, H, g0)
        assert np.allclose(pen, g0 * E / (E + c * H), rtol=1e-8)
        pens.append(pen.max())
    assert all(a > b for a, b in zip(pens, pens[1:]))
    assert pens[-1] < 1e-3 * g0


@pytest.mark.parametrize("example, mode", [("2.3-ex1", "running"), ("2.3-ex3", "recursive")])
def test_memory_variants_agree(tmp_path, example, mode):
    """O(1) updates against the plain O(n) sum of (2.136): same fields to round-off."""
    base = ["run", example, "--n", "4", "--k", "0.05", "--no-figures", "--quiet"]
    run_cli(base + ["--set", f"memory_mode={mode}", "--out", tmp_path / "fast"])
    run_cli(base + ["--set", "memory_mode=sum", "--out", tmp_path / "sum"])
    (_, fast), (_, plain) = load_run(tmp_path / "fast"), load_run(tmp_path / "sum")
    for name in ("u", "zeta", "von_mises"):
        assert rel_diff(fast[name], plain[name]) < 1e-12, name
    assert np.abs(fast["u"]).max() > 1e-3  # a real run


def test_memory_mode_must_match_kernel(tmp_path):
    proc = run_cli(["run", "2.3-ex3", "--n", "4", "--set", "memory_mode=running", "--quiet",
                    "--out", tmp_path], check=False)
    assert proc.returncode == 2 and "does not apply" in proc.stderr


@pytest.mark.mpi
def test_example1_serial_equals_two_ranks(tmp_path):
    serial_and_two_ranks(tmp_path, ["run", "2.3-ex1", "--n", "8", "--k", "0.05", "--no-figures",
                                    "--quiet"])
    serial, parallel = history(tmp_path / "s"), history(tmp_path / "p")
    assert serial.keys() == parallel.keys()
    for t, row in serial.items():  # ||sigma_n||_L2, summed per cell on each rank's cells
        assert abs(float(parallel[t]["stress_L2"]) / float(row["stress_L2"]) - 1) < 1e-8, t


def history(folder):
    with open(folder / "history.csv") as f:
        return {round(float(r["t"]), 8): r for r in csv.DictReader(f)}


def test_example2_memory_pulls_back(tmp_path):
    """Figure 2.17: under a constant load the stiffening memory shrinks the deformation."""
    run_cli(["run", "2.3-ex2", "--n", "4", "--no-figures", "--quiet", "--out", tmp_path])
    h = history(tmp_path)
    ratio = float(h[2.0]["eps_u_L2"]) / float(h[0.0]["eps_u_L2"])
    print(f"||eps(u)|| at t = 2 / at t = 0: {ratio:.3f}")
    assert ratio < 0.5
    assert float(h[2.0]["zeta_min"]) < 1.0  # the body is damaged


def test_example3_fading_memory_and_residual_stress(tmp_path):
    """Figures 2.20-2.21: larger deformation at t = 0.5 than at t = 0 under the same load, and
    a nonzero residual stress at t = 1 after the load is removed."""
    run_cli(["run", "2.3-ex3", "--n", "4", "--no-figures", "--quiet", "--out", tmp_path])
    h = history(tmp_path)
    u0, u_half, u1 = (float(h[t]["u_L2"]) for t in (0.0, 0.5, 1.0))
    s_half, s1 = float(h[0.5]["stress_L2"]), float(h[1.0]["stress_L2"])
    print(f"||u||: t=0 {u0:.4f}, t=0.5 {u_half:.4f}, t=1 {u1:.4f}; ||sigma||: t=0.5 {s_half:.3f}, t=1 {s1:.3f}")
    assert u_half > 1.2 * u0
    # unloaded at t = 1: the memory leaves a residual deformation and a small self-equilibrated
    # stress (without memory both would vanish exactly)
    assert u1 > 0.2 * u0
    assert s1 > 1e-4 * s_half


def _split_test_model():
    """(model, geometry): a 2.3 model on a 6 x 6 unit square, clamped on top, Gamma_C at the
    bottom, constant memory kernel (the set-up of the split tests)."""
    params = ModelParameters(E=100.0, nu=0.3, variant="A", lam_D=0.0, lam_u=0.0, kappa=1.0,
                             stop_at_zeta_star=False,
                             extra={"c_nu": 1e3, "gap": 0.0, "memory_kernel": "constant"})
    geo = rectangle(MPI.COMM_WORLD, (0, 0), (1, 1), 6, 6,
                    {GAMMA_D: side(1, 1.0), GAMMA_C: side(1, 0.0)})
    return ViscoelasticMemoryContact(Problem("2.3", geo, 1.0, k=1.0, params=params,
                                             name="split-test")), geo


def test_split_jacobian_equals_assembly():
    """The 2.3 Jacobian split (constant cell part once, Gamma_C term per Newton step)
    equals the full assembly, Dirichlet rows included, at a state in contact on part of Gamma_C;
    a residual whose cell part depends on u is not split."""
    import ufl
    from damage_dolfinx.numerics.boundary import clamped
    from damage_dolfinx.numerics.callbacks import constant_cell_jacobian, form_callbacks, relative_change
    from damage_dolfinx.forms.viscoelastic_memory import displacement_residual
    from damage_dolfinx.geometries import GAMMA_N
    s, geo = _split_test_model()
    V = s.u.function_space
    X = V.tabulate_dof_coordinates()
    s.u.x.array.reshape(-1, 2)[:, 1] = -0.01 * np.sin(7.0 * X[:, 0])  # contact where < 0
    ds = ufl.Measure("ds", domain=s.mesh, subdomain_data=geo.facet_tags)
    F = displacement_residual(s.u, ufl.TestFunction(V), s.memory.M, 100.0, 0.3, 1e3, 0.0,
                              ufl.FacetNormal(s.mesh), None, None, ds(GAMMA_N), ds(GAMMA_C))
    J = ufl.derivative(F, s.u, ufl.TrialFunction(V))
    bcs = [clamped(V, geo.facet_tags, GAMMA_D)]
    split = constant_cell_jacobian(F, s.u)
    assert split is not None
    _, full, _, A = form_callbacks(F, J, s.u, bcs)
    _, split_jacobian, _, B = form_callbacks(F, J, s.u, bcs, split)
    full(None, A)
    split_jacobian(None, B)
    assert relative_change(B, A) < 1e-13
    in_contact = A.duplicate(copy=True)
    s.u.x.array[:] = 0.0
    full(None, A)
    assert relative_change(in_contact, A) > 1e-3  # the Gamma_C term was active above
    w = ufl.TestFunction(V)
    assert constant_cell_jacobian(ufl.inner(s.u, s.u) * ufl.inner(s.u, w) * ufl.dx
                                  + ufl.inner(s.u, w) * ds(GAMMA_C), s.u) is None


def test_split_residual_and_jacobian_key():
    """The 2.3 residual F(x_0) + K (x - x_0) + (r(x) - r(x_0)) (split_residual.py, r the
    Gamma_C term) equals the assembled one: bit for bit at x_0, to round-off elsewhere, at a
    state in partial contact with a nonzero memory; the Jacobian key (the assembled Gamma_C
    Jacobian) is unchanged while the contact set is and changes with it."""
    from damage_dolfinx import compat
    from damage_dolfinx.numerics.split_residual import SplitResidual
    s, _ = _split_test_model()
    assert isinstance(s._residual, SplitResidual)
    rng = np.random.default_rng(3)
    s.memory.M.x.array[:] = rng.standard_normal(s.memory.M.x.array.size)
    X = s.u.function_space.tabulate_dof_coordinates()
    s.u.x.array.reshape(-1, 2)[:, 1] = -0.01 * np.sin(7.0 * X[:, 0])  # contact where < 0
    s.u.x.array.reshape(-1, 2)[np.isclose(X[:, 1], 1.0)] = 0.0         # the clamped side
    s._residual.begin()  # x_0 = u
    x = compat.petsc_vec(s.u).copy()
    b_form, b_split = x.duplicate(), x.duplicate()
    s.mech.form_residual(x, b_form)
    s._residual(x, b_split)
    assert np.array_equal(b_split.array, b_form.array)
    key = s._residual.jacobian_key(x)
    x.scale(1.5)  # the same contact set
    s.mech.form_residual(x, b_form)
    s._residual(x, b_split)
    assert np.array_equal(s._residual.jacobian_key(x), key)
    b_split.axpy(-1.0, b_form)
    assert b_split.norm() <= 1e-13 * b_form.norm()
    x.scale(-1.0)  # the complementary contact set
    s._residual(x, b_split)
    assert not np.array_equal(s._residual.jacobian_key(x), key)


@pytest.mark.parametrize("dim", [2, 3])
def test_cellwise_memory_integrand_equals_interpolation(dim):
    """g = zeta Phi_L(B eps(u)) from the stress at one point per cell times zeta's vertex
    values equals the interpolation of g into DG1 (Phi_L clipping half the components)."""
    from dolfinx import fem, mesh
    from damage_dolfinx import compat
    from damage_dolfinx.forms.viscoelastic_memory import memory_integrand, memory_stress
    from damage_dolfinx.numerics.memory import CellwiseIntegrand
    comm = MPI.COMM_WORLD
    msh = (mesh.create_unit_square(comm, 6, 5) if dim == 2
           else mesh.create_unit_cube(comm, 3, 3, 2))
    V, Z = compat.vector_p1(msh), compat.scalar_p1(msh)
    G = compat.function_space(msh, "DG", 1, (dim, dim))
    u, zeta, g, g_ref = fem.Function(V), fem.Function(Z), fem.Function(G), fem.Function(G)
    rng = np.random.default_rng(1)
    u.x.array[:] = rng.standard_normal(u.x.array.size)
    zeta.x.array[:] = rng.uniform(0.01, 1.0, zeta.x.array.size)
    for f in (u, zeta):
        f.x.scatter_forward()
    E, nu, L = 100.0, 0.3, 150.0
    compat.interpolate(g_ref, compat.expression(memory_integrand(u, zeta, E, nu, None), G))
    unclipped = g_ref.x.array.copy()
    compat.interpolate(g_ref, compat.expression(memory_integrand(u, zeta, E, nu, L), G))
    assert not np.allclose(unclipped, g_ref.x.array)  # Phi_L clips some components
    CellwiseIntegrand(memory_stress(u, E, nu, L), zeta, G)(g)
    print("max difference", np.abs(g.x.array - g_ref.x.array).max())
    assert np.abs(g.x.array - g_ref.x.array).max() <= 1e-14 * np.abs(g_ref.x.array).max()


@pytest.mark.parametrize("example, n", [("2.3-ex1", 8), ("2.3-ex1-3d", 3)])
def test_stress_norm_per_cell_equals_assembly(tmp_path, example, n):
    """||sigma_n||_L2^2 summed per cell in NumPy (bookkeeping.AffineStressNorm: B eps(u_n)
    constant and M_n linear on each simplex) equals the assembled form after a few steps
    (nonzero memory), on every rank count."""
    import damage_dolfinx as dd
    from damage_dolfinx import compat
    seen = 0
    with dd.steps(example, tmp_path / "o", n=n, k=0.05, T=0.2, progress=False,
                  figures=False) as run:
        for step in run:
            model = step.model
            assert model._stress_norm is not None
            cellwise = model.comm.allreduce(model._stress_norm.local())
            assembled = compat.assemble_scalar(model._stress_sq, model.comm)
            print(step.n, cellwise, assembled)
            assert abs(cellwise - assembled) <= 1e-13 * assembled
            seen += step.n > 0 and np.abs(model.memory.M.x.array).max() > 0
    assert seen >= 3
