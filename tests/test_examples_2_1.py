"""Section 2.1 examples end to end through the CLI: serial = mpirun -n 2, physics checks,
failure handling. Small meshes; the thesis-size studies live in benchmarks/."""
import csv
import json

import numpy as np
import pytest

from conftest import load_run, rel_diff, run_cli, serial_and_two_ranks


@pytest.mark.mpi
def test_example1_serial_equals_two_ranks(tmp_path):
    (s_sum, _), (p_sum, _) = serial_and_two_ranks(
        tmp_path, ["run", "2.1-ex1", "--n", "10", "--k", "0.05", "--no-figures", "--quiet"])
    for key in ("u_L2", "eps_u_L2", "zeta_min", "zeta_max"):
        assert p_sum["final"][key] == pytest.approx(s_sum["final"][key], rel=1e-8)
    # the run really damaged the body, and the history has every step
    assert s_sum["status"] == "completed" and s_sum["steps_done"] == 20
    assert s_sum["final"]["zeta_min"] < 0.97
    with open(tmp_path / "s" / "history.csv") as f:
        assert len(list(csv.DictReader(f))) == 21


def test_summary_contract(tmp_path):
    run_cli(["run", "2.1-ex1", "--n", "5", "--k", "0.1", "--quiet", "--out", tmp_path])
    summary = json.loads((tmp_path / "summary.json").read_text())
    for key in ("schema", "example", "parameters", "n", "k", "T", "num_steps", "steps_done",
                "mpi_size", "wall_time_s", "iterations", "final", "assumptions", "environment"):
        assert key in summary, key
    assert summary["num_steps"] == 10 and summary["parameters"]["kappa"] == 1.0
    for key in ("u_L2", "eps_u_L2", "zeta_min", "zeta_max"):
        assert np.isfinite(summary["final"][key])
    assert summary["iterations"]["damage_ksp"] >= 10
    xdmf = (tmp_path / "fields.xdmf").read_text()
    assert xdmf.count('<Time Value="') == 11  # one grid per written time ...
    assert xdmf.count('<Attribute Name="') == 3 * 11  # ... holding u, zeta and von Mises
    assert (tmp_path / "fields.h5").stat().st_size > 0
    assert (tmp_path / summary["outputs"]["figures"][0]["file"]).stat().st_size > 10_000


def test_example2_tension_vs_compression(tmp_path):
    """Figures 2.4/2.5: the two damage maps differ clearly, the stresses stay alike."""
    for ex in ("2.1-ex2a", "2.1-ex2b"):
        run_cli(["run", ex, "--h", "0.25", "--k", "0.02", "--no-figures", "--quiet",
                 "--out", tmp_path / ex])
    (_, a), (_, b) = load_run(tmp_path / "2.1-ex2a"), load_run(tmp_path / "2.1-ex2b")
    damage_a, damage_b = 1 - a["zeta"], 1 - b["zeta"]
    damage_gap = rel_diff(damage_a, damage_b)
    stress_gap = rel_diff(a["von_mises"], b["von_mises"])
    print(f"relative difference: damage (1-zeta) {damage_gap:.3f}, von Mises {stress_gap:.4f}")
    assert damage_gap > 0.1 and stress_gap < 0.05
    assert damage_gap > 5 * stress_gap
    # the most damaged point moves to the other side of a diamond corner (measured at h = 0.1,
    # kappa = 1: (0.07, 0.93) for tension vs (0.93, 0.07) for compression)
    worst_a = a["zeta_coords"][np.argmax(damage_a)]
    worst_b = b["zeta_coords"][np.argmax(damage_b)]
    print(f"most damaged point: tension {worst_a}, compression {worst_b}")
    assert np.linalg.norm(worst_a - worst_b) > 0.5


def test_stop_at_zeta_star(tmp_path):
    """G43: with a huge tension coefficient the run stops when zeta reaches zeta_star."""
    run_cli(["run", "2.1-ex1", "--n", "5", "--k", "0.05", "--set", "lam_u_plus=1e8",
             "--no-figures", "--quiet", "--out", tmp_path])
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["status"] == "zeta_star_reached"
    assert summary["final"]["zeta_min"] <= 0.01
    assert summary["steps_done"] < summary["num_steps"]


def test_solver_failure_is_reported_and_keeps_finished_steps(tmp_path):
    """A KSP that cannot converge raises a clear error naming example, step, time, residual;
    the history of the finished steps stays on disk."""
    proc = run_cli(["run", "2.1-ex1", "--n", "10", "--k", "0.1", "--quiet", "--out", tmp_path,
                    "-mech_pc_type", "jacobi", "-mech_ksp_max_it", "3"], check=False)
    assert proc.returncode == 3
    msg = proc.stderr.strip().splitlines()[-1]
    # t = 0 has zero load (converges trivially); the first loaded step fails
    for word in ("mech_ksp did not converge", "example 2.1-ex1", "step 1", "t = 0.1", "residual"):
        assert word in msg, msg
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["status"] == "failed" and "residual" in summary["error"]
    with open(tmp_path / "history.csv") as f:
        assert [row["step"] for row in csv.DictReader(f)] == ["0"]
