"""Section 2.4: exact Q^h projections, P2 reduces to P1, serial = mpirun -n 2, and Example 2
(the contact side does not slip; the most damaged point is the lower right contact corner)."""
import csv

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from conftest import load_run, rel_diff, run_cli, serial_and_two_ranks
from damage_dolfinx import compat
from damage_dolfinx.forms.constitutive import B_plane_stress, eps
from damage_dolfinx.forms.viscoplastic import viscoplastic_rate


def _l2_projection_dg0(expr, Q):
    """Cell-wise L2 projection onto DG0 tensors: (P expr)_K = int_K expr / |K| (assembled)."""
    q = ufl.TestFunction(Q)
    b = fem.Function(Q)
    compat.assemble_vector(compat.petsc_vec(b), compat.form(ufl.inner(expr, q) * ufl.dx))
    area = fem.Function(compat.scalar_dg0(Q.mesh))
    compat.assemble_vector(compat.petsc_vec(area),
                           compat.form(ufl.TestFunction(area.function_space) * ufl.dx))
    cells = compat.cell_dofs(Q)[:, 0]
    return b.x.array.reshape(-1, 4)[cells] / area.x.array[compat.cell_dofs(area.function_space)[:, 0]][:, None]


def test_q_projection_of_p1_strain_and_rate_is_exact(unit_square):
    """P_Q[B eps(w)] (w in P1) and P_Q[(1 - zeta) Phi_L(sigma)] (zeta in P1, sigma in Q^h) are
    the centroid values the stepper interpolates: they match the assembled L2 projection."""
    msh = unit_square(6)
    V, Z, Q = compat.vector_p1(msh), compat.scalar_p1(msh), compat.tensor_dg0(msh)
    w, zeta, sigma = fem.Function(V), fem.Function(Z), fem.Function(Q)
    w.interpolate(lambda X: np.vstack([np.sin(3 * X[0] * X[1]), X[0] ** 2 - X[1]]))
    zeta.interpolate(lambda X: 0.2 + 0.7 * X[0] * X[1])
    compat.interpolate(sigma, compat.expression(1e4 * eps(w), Q))  # entries beyond L = 1000
    for expr in (B_plane_stress(eps(w), 1000.0, 0.3), viscoplastic_rate(sigma, zeta, 1000.0)):
        centroid = fem.Function(Q)
        compat.interpolate(centroid, compat.expression(expr, Q))
        cells = compat.cell_dofs(Q)[:, 0]
        got = centroid.x.array.reshape(-1, 4)[cells]
        want = _l2_projection_dg0(expr, Q)
        assert np.abs(got - want).max() <= 1e-12 * np.abs(want).max()
        assert np.abs(want).max() > 1.0


def _run(tmp_path, name, *args):
    base = ["run", "2.4-ex1", "--n", "8", "--k", "0.02", "--T", "0.4", "--no-figures", "--quiet"]
    run_cli(base + list(args) + ["--out", tmp_path / name])
    return load_run(tmp_path / name)


def test_coulomb_reduces_to_tresca_when_mu_S_equals_g(tmp_path):
    """P2 with the normal constraint kept (v.nu = 0 absorbs the prescribed S_n) and bound
    mu_f |S_n| = 0.07 * 10 is P1 with g = 0.7; the literal P2 (free normal motion) differs."""
    _, p1 = _run(tmp_path, "p1", "--friction-law", "tresca", "--set", "g_fric=0.7")
    _, p2 = _run(tmp_path, "p2", "--friction-law", "coulomb", "--set", "mu_f=0.07",
                 "--set", "S_n=10", "--set", "coulomb_normal=bilateral")
    for name in ("u", "zeta", "von_mises"):
        assert rel_diff(p2[name], p1[name]) < 1e-10, name
    _, free = _run(tmp_path, "free", "--friction-law", "coulomb", "--set", "mu_f=0.07")
    assert rel_diff(free["u"], p1["u"]) > 1e-3


def test_newton_matches_penalty_duality(tmp_path):
    """The regularised Newton and the Bermudez-Moreno iteration solve the same increment VI."""
    _, newton = _run(tmp_path, "newton", "--set", "friction_tol=1e-10")
    _, pd = _run(tmp_path, "pd", "--friction-solver", "penalty-duality", "--set", "friction_tol=1e-10")
    assert rel_diff(pd["u"], newton["u"]) < 1e-6


def test_serial_equals_two_ranks_and_bounds(tmp_path):
    for law in ("tresca", "coulomb"):
        (_, s), _ = serial_and_two_ranks(
            tmp_path / law, ["run", "2.4-ex1", "--friction-law", law, "--n", "8", "--k", "0.05",
                             "--no-figures", "--quiet"], fields=("u", "zeta", "von_mises", "sigma"))
        assert s["zeta"].min() >= 0.01 - 1e-12 and s["zeta"].max() <= 1 + 1e-12


def test_example_2_contact_side_sticks_and_lower_right_corner_damages_first(tmp_path):
    run_cli(["run", "2.4-ex2", "--n", "16", "--k", "0.01", "--T", "0.5", "--no-figures",
             "--quiet", "--out", tmp_path])
    with open(tmp_path / "history.csv") as f:
        rows = list(csv.DictReader(f))
    u_max = max(float(r["u_L2"]) for r in rows)
    slip = max(float(r["slip_max"]) for r in rows)
    print(f"max tangential displacement on Gamma_C {slip:.2e}, ||u||_L2 up to {u_max:.3f}")
    assert slip < 1e-8 * u_max
    first = next(r for r in rows if float(r["zeta_min"]) < 1.0 - 1e-9)
    x, y = float(first["zeta_min_x"]), float(first["zeta_min_y"])
    print(f"first damaged node ({x}, {y}) at t = {first['t']}")
    assert x >= 0.85 and y <= 0.1
