"""Section 3.2: the discrete momentum balance of a sliding block (closed form), the three friction
solvers agree, the damage bounds hold, serial = mpirun -n 2, and Example 2's stuck lower face."""
import csv

import numpy as np
import pytest
import ufl
from mpi4py import MPI

from conftest import load_run, rel_diff, run_cli, serial_and_two_ranks


def _block_stepper(f, g, rho, k=0.02, T=0.1, L=2.0, H=1.0):
    """Block (0,L)x(0,H) on a Tresca plane (bottom, bound g), no Gamma_D, uniform body force
    (f, 0), no damage source."""
    from damage_dolfinx.geometries import GAMMA_C
    from damage_dolfinx.geometries.rectangle import rectangle, side
    from damage_dolfinx.core.parameters import ModelParameters
    from damage_dolfinx.problem.problem import Problem
    from damage_dolfinx.models.dynamic_tresca_3_2 import DynamicTresca
    geometry = rectangle(MPI.COMM_WORLD, (0, 0), (L, H), 8, 4, {GAMMA_C: side(1, 0.0)})
    params = ModelParameters(
        E=1e4, nu=0.3, kappa=1.0, zeta_star=0.01, variant="A", lam_D=0.0, lam_u=0.0, lam_w=0.0,
        L_trunc=1000.0, stop_at_zeta_star=False,
        extra={"rho": rho, "m_visc": 100.0, "g_fric": g, "eps_reg": 1e-9,
               "friction_solver": "newton", "stability_check": "off"}).validate()
    data = Problem("3.2", geometry, T, k=k, params=params, name="block",
                       body_force=lambda x, t: ufl.as_vector((f, 0.0)),
                       builders={"contact_faces": {"bottom": lambda X: np.isclose(X[1], 0.0)}})
    return DynamicTresca(data)


def test_sliding_block_momentum_balance():
    """With every contact node slipping forwards, w = (1, 0) in (3.95) (eps(w) = 0) gives
    rho (V_n - V_{n-1}) area / k = f area - g L for V_n = mean horizontal velocity: V_n = n k
    (f - g L / area) / rho, independent of the elastic and viscous terms."""
    f, g, rho, k, L, H = 10.0, 2.0, 2.0, 0.02, 2.0, 1.0
    s = _block_stepper(f, g, rho, k=k, L=L, H=H)
    s.initialize()
    from damage_dolfinx import compat
    mean_v1 = compat.form(s.v[0] * ufl.dx)
    for n in range(1, 6):
        s.advance()
        V = compat.assemble_scalar(mean_v1, MPI.COMM_WORLD) / (L * H)
        exact = n * k * (f - g * L / (L * H)) / rho
        assert abs(V - exact) < 1e-9 * exact, (n, V, exact)
    assert s.zeta_min() == 1.0  # no damage source


def test_sticking_block():
    """Total driving force f area = g L / 8: the contact nodes stick (|v_tau| <= eps_reg, so
    |u_tau| <= T eps_reg = 1e-10) while the body deforms elastically. (At f area = g L / 4 the
    stress concentration lets the corner node x = (L, 0) slip: stick needs more than the total
    force balance.)"""
    s = _block_stepper(f=0.5, g=2.0, rho=1.0, T=0.1)
    s.initialize()
    for _ in range(s.num_steps):
        s.advance()
    assert s.u_tau_max()["u_tau_max_bottom"] < 1e-10
    assert s.scalars()["u_L2"] > 1e-6


def test_three_friction_solvers_agree(tmp_path):
    """Newton (eps = 1e-9), Uzawa and penalty-duality on 3.2-ex1 (stopping tests at 1e-10)."""
    base = ["run", "3.2-ex1", "--n", "8", "--k", "0.02", "--T", "0.3", "--no-figures", "--quiet",
            "--set", "friction_tol=1e-10"]
    runs = {}
    for solver in ("newton", "uzawa", "penalty-duality"):
        run_cli(base + ["--set", f"friction_solver={solver}", "--out", tmp_path / solver])
        runs[solver] = load_run(tmp_path / solver)
    summary, newton = runs["newton"]
    # k = 0.02 lies below the no-eigensolve bound, so the run records the bound, not k_max
    assert 0.02 <= summary["k_max_lower_bound"] < 0.0201
    from damage_dolfinx.catalogue import examples
    from damage_dolfinx.numerics.stability_bound import exact_estimates
    with exact_estimates():
        k_max = examples.get("3.2-ex1").build(MPI.COMM_WORLD, n=8, k=0.02, T=0.3).k_max
    assert 0.02 <= k_max < 0.0201  # k_max -> 2/m_visc from above
    for solver in ("uzawa", "penalty-duality"):
        summary, fields = runs[solver]
        assert summary["iterations"]["friction_solver"] == solver
        assert rel_diff(fields["u"], newton["u"]) < 1e-6, solver
        assert rel_diff(fields["zeta"], newton["zeta"]) < 1e-6, solver


def test_uzawa_is_refused_without_gamma_D(tmp_path):
    proc = run_cli(["run", "3.2-ex2", "--n", "2", "--set", "friction_solver=uzawa", "--quiet",
                    "--out", tmp_path], check=False)
    assert proc.returncode == 2 and "Gamma_D" in proc.stderr


def test_damage_bounds_and_serial_equals_two_ranks(tmp_path):
    """3.2-ex1 with a strong damage source (lam_u = 1e5): zeta reaches zeta_star and stays in
    [zeta_star, 1]; the same run on 2 ranks gives the same fields."""
    (_, s), _ = serial_and_two_ranks(
        tmp_path, ["run", "3.2-ex1", "--n", "8", "--k", "0.02", "--T", "0.6", "--no-figures",
                   "--quiet", "--set", "lam_u=1e5"])
    assert s["zeta"].min() >= 0.01 - 1e-12 and s["zeta"].max() <= 1 + 1e-12
    assert s["zeta"].min() <= 0.01 + 1e-9
    with open(tmp_path / "s" / "history.csv") as f:
        assert min(float(r["zeta_min"]) for r in csv.DictReader(f)) >= 0.01 - 1e-12


@pytest.mark.mpi
def test_example2_serial_equals_two_ranks_and_lower_face_stuck(tmp_path):
    """Example 2 (16 x 8 cells, k = 0.01, T = 1): the lower face (g = 1000) stays stuck, the
    upper one (g = 1) slides; the history column is the same on 1 and 2 ranks."""
    serial, parallel = serial_and_two_ranks(
        tmp_path, ["run", "3.2-ex2", "--n", "4", "--k", "0.01", "--T", "1", "--no-figures",
                   "--quiet"])
    rows = {}
    for name in ("s", "p"):
        with open(tmp_path / name / "history.csv") as f:
            rows[name] = list(csv.DictReader(f))[1:]
    top = np.array([float(r["u_tau_max_top"]) for r in rows["s"]])
    bottom = np.array([float(r["u_tau_max_bottom"]) for r in rows["s"]])
    top_p = np.array([float(r["u_tau_max_top"]) for r in rows["p"]])
    print(f"max |u_tau| top {top.max():.3e}, bottom {bottom.max():.3e}")
    assert top.max() > 1e-3
    assert bottom.max() < 1e-8 * top.max()
    assert np.allclose(top, top_p, rtol=1e-7, atol=1e-12)
