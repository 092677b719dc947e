"""Parameter sweeps (``damage-dolfinx sweep``, :func:`damage_dolfinx.sweep`): every point a run
folder, interrupted sweeps resumed keeping their finished points, the points shared out among
the ranks, a CSV of every point and a plot, bad grids refused before any work."""
import csv
import json
import subprocess
import sys

import pytest

from conftest import ENV

CLI = [sys.executable, "-m", "damage_dolfinx.cli"]
TINY = ["2.2-ex1", "--n", "4", "--T", "0.04", "--k", "0.01", "--no-figures", "--quiet"]
GRID = ["--set", "kappa=0.01,0.1,1", "--set", "lam_u=500,1000"]


def cli(*args, np_=1):
    cmd = CLI + [str(a) for a in args]
    if np_ > 1:
        cmd = ["mpirun", "-n", str(np_)] + cmd
    return subprocess.run(cmd, capture_output=True, text=True, env=ENV, timeout=600)


def rows(folder):
    with open(folder / "sweep.csv", newline="") as f:
        return list(csv.DictReader(f))


def test_sweep_interrupted_after_three_points_resumes_keeping_them(tmp_path):
    out = tmp_path / "sweep"
    r = cli("sweep", *TINY, *GRID, "--max-points", "3", "--out", out)
    assert r.returncode == 0, r.stderr
    first = rows(out)
    assert [row["status"] for row in first] == ["completed"] * 3 + ["pending"] * 3
    mapping = json.loads((out / "points.json").read_text())
    assert [p["values"] for p in mapping["points"]] == [
        {"kappa": kappa, "lam_u": lam_u} for kappa in (0.01, 0.1, 1.0) for lam_u in (500.0, 1000.0)]
    kept = {i: (out / f"point_{i}" / "summary.json").read_bytes() for i in range(3)}
    stamps = {i: (out / f"point_{i}" / "summary.json").stat().st_mtime_ns for i in range(3)}
    assert not (out / "point_3").exists()

    r = cli("sweep", *TINY, *GRID, "--out", out)
    assert r.returncode == 0, r.stderr
    final = rows(out)
    assert [row["status"] for row in final] == ["completed"] * 6
    for i in range(3):  # the finished points are kept as they were
        assert (out / f"point_{i}" / "summary.json").read_bytes() == kept[i]
        assert (out / f"point_{i}" / "summary.json").stat().st_mtime_ns == stamps[i]
    for row in final:
        for column in ("u_L2", "zeta_min", "zeta_max", "steps_done"):
            assert row[column] != "", (row, column)
        summary = json.loads((out / row["folder"] / "summary.json").read_text())
        assert summary["parameters"]["kappa"] == float(row["kappa"])
        assert summary["parameters"]["lam_u"] == float(row["lam_u"])
    assert (out / "sweep.png").stat().st_size > 1000
    assert json.loads((out / "summary.json").read_text())["completed"] == 6


@pytest.mark.mpi
def test_points_are_shared_out_among_two_ranks(tmp_path):
    out = tmp_path / "sweep"
    r = cli("sweep", *TINY, "--set", "lam_u=500,1000", "--out", out, np_=2)
    assert r.returncode == 0, r.stderr
    for row in rows(out):
        assert row["status"] == "completed"
        summary = json.loads((out / row["folder"] / "summary.json").read_text())
        assert summary["mpi_size"] == 1  # each point serially, on its own rank


@pytest.mark.parametrize("grid, expected", [
    (["--set", "kappa="], "empty list"),
    (["--set", "kappa=0.1,nan"], "not finite"),
    (["--set", "kappa=0.1,inf"], "not finite"),
    (["--set", "bogus=1,2"], "unknown parameter 'bogus'"),
    (["--set", "kappa=1,1"], "given twice"),
    (["--set", "kappa=0.1", "--set", "kappa=1"], "given twice"),
    (["--set", "kappa=0.1,,1"], "empty value"),
    (["--set", "kappa=0.1,-1"], "kappa must be >= 0"),
    ([], "at least one --set"),
])
def test_bad_grids_are_refused_before_any_work(tmp_path, grid, expected):
    out = tmp_path / "sweep"
    r = cli("sweep", *TINY, *grid, "--out", out)
    assert r.returncode == 2, (r.stdout, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and expected in lines[0], r.stderr
    assert not out.exists()


def test_another_grid_in_a_sweep_folder_is_refused(tmp_path):
    out = tmp_path / "sweep"
    assert cli("sweep", *TINY, "--set", "lam_u=500", "--out", out).returncode == 0
    r = cli("sweep", *TINY, "--set", "lam_u=700", "--out", out)
    assert r.returncode == 2 and "holds another sweep" in r.stderr, r.stderr
    assert (out / "point_0" / "summary.json").is_file()


def test_api_sweep_of_an_own_problem(tmp_path):
    import ufl
    import damage_dolfinx as dd
    from damage_dolfinx.geometries.rectangle import rectangle, side

    def mesh(comm, n):
        return rectangle(comm, (0.0, 0.0), (2.0, 0.5), 4 * n, n,
                         {1: side(0, 0.0), 2: side(0, 2.0), 3: side(1, 0.0)})

    problem = dd.Problem(model="2.2", mesh=mesh, n=2, T=0.04, k=0.01,
                         boundaries={"clamped": 1, "traction": 2, "tresca": 3},
                         traction=lambda x, t: ufl.as_vector((40.0 * t, 0.0)),
                         params={"E": 2000.0, "g_fric": 10.0})
    summary = dd.sweep(problem, tmp_path / "own", {"lam_u": [1e3, 1e4]}, figures=False,
                       progress=False)
    assert summary["completed"] == 2 and summary["plot"] == "sweep.png"
    zeta = [float(r["zeta_min"]) for r in rows(tmp_path / "own")]
    assert zeta[1] < zeta[0] < 1  # more damage with the larger rate
    with pytest.raises(dd.InputError, match="empty list"):
        dd.sweep(problem, tmp_path / "bad", {"lam_u": []})
    assert not (tmp_path / "bad").exists()
