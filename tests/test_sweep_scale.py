"""Sweeps that scale out: groups of ranks each running one point in parallel
(``--ranks-per-point``) and one point per job of a job array (``--point``), both giving the
serial sweep's table; the refusals of both; and the collective outcome with groups (a failure
on every rank of a group fails that point only, one on some ranks of a group ends the whole
sweep within seconds with one line and the statuses written)."""
import csv
import json
import math
import subprocess
import sys
import textwrap
import time

import pytest

from conftest import ENV, tool_lines

CLI = [sys.executable, "-m", "damage_dolfinx.cli"]
TINY = ["sweep", "2.2-ex1", "--n", "4", "--T", "0.04", "--k", "0.01", "--no-figures", "--quiet",
        "--set", "kappa=0.01,0.1", "--set", "lam_u=500,1000"]
#: columns that differ between two runs of the same points (not results)
NOT_RESULTS = {"wall_time_s", "folder"}


def cli(*args, np_=1, timeout=300):
    cmd = CLI + [str(a) for a in args]
    if np_ > 1:
        cmd = ["mpirun", "-n", str(np_), "--oversubscribe"] + cmd
    return subprocess.run(cmd, capture_output=True, text=True, env=ENV, timeout=timeout)


def table(folder):
    with open(folder / "sweep.csv", newline="") as f:
        return list(csv.DictReader(f))


def assert_same_table(got, expected, rel=1e-8):
    """Every column of sweep.csv equal, numbers to the solvers' tolerance (relative)."""
    assert [r["point"] for r in got] == [r["point"] for r in expected]
    assert list(got[0]) == list(expected[0])
    worst = 0.0
    for a, b in zip(got, expected):
        for column in a:
            if column in NOT_RESULTS:
                continue
            try:
                x, y = float(a[column]), float(b[column])
            except ValueError:
                assert a[column] == b[column], (column, a, b)
                continue
            assert math.isfinite(x) and math.isclose(x, y, rel_tol=rel, abs_tol=1e-14), \
                (column, a["point"], x, y)
            worst = max(worst, abs(x - y))
    print(f"max abs difference of sweep.csv columns: {worst:.2e}")


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    out = tmp_path_factory.mktemp("serial") / "sweep"
    r = cli(*TINY, "--out", out)
    assert r.returncode == 0, r.stderr
    rows = table(out)
    assert [row["status"] for row in rows] == ["completed"] * 4
    return rows


@pytest.mark.mpi
@pytest.mark.parametrize("ranks, per_point", [(4, 2), (2, 2)])
def test_groups_of_ranks_give_the_serial_table(tmp_path, serial, ranks, per_point):
    out = tmp_path / "sweep"
    r = cli(*TINY, "--ranks-per-point", per_point, "--out", out, np_=ranks)
    assert r.returncode == 0, r.stderr
    assert_same_table(table(out), serial)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "completed"
    assert (summary["ranks_per_point"], summary["groups"]) == (per_point, ranks // per_point)
    for i in range(4):  # each point in parallel on its group
        assert json.loads((out / f"point_{i}" / "summary.json").read_text())["mpi_size"] == \
            per_point


OPENER = textwrap.dedent("""
    import sys, time
    from pathlib import Path
    from mpi4py import MPI
    from damage_dolfinx.studies.sweep_folder import open_sweep
    root, point, start, rounds = Path(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3]), \\
        int(sys.argv[4])
    mapping = {"schema": "damage-dolfinx/sweep/v1", "case": "2.2-ex1",
               "grid": {"kappa": [1, 2, 3, 4]}, "n": 4, "k": 0.01, "T": 0.04,
               "points": [{"index": i, "folder": f"point_{i}", "values": {"kappa": i + 1}}
                          for i in range(4)]}
    for j in range(rounds):  # the jobs open folder s<j> at the same instant
        out = root / f"s{j}"
        out.mkdir(exist_ok=True)
        while time.time() < start + 0.05 * j:
            time.sleep(0.0005)
        try:
            open_sweep(out, mapping, point, MPI.COMM_SELF)
            (out / f"point_{point}").mkdir(exist_ok=True)  # its run starts
        except Exception as exc:
            print(f"folder s{j}: {type(exc).__name__}: {exc}", file=sys.stderr)
""")


def test_point_jobs_opening_one_folder_at_the_same_instant_never_refuse(tmp_path):
    """The opening of a sweep folder by the jobs of a job array, without solving: 4 jobs open
    each of 40 fresh folders at the same instant; none is refused or fails (one job, half-way
    through writing the folder, once made another's check fail with a KeyError)."""
    script = tmp_path / "opener.py"
    script.write_text(OPENER)
    start = time.time() + 4.0  # after the imports of every job
    jobs = [subprocess.Popen([sys.executable, str(script), str(tmp_path), str(i), str(start),
                              "40"], stderr=subprocess.PIPE, text=True, env=ENV)
            for i in range(4)]
    errors = [job.communicate(timeout=120)[1] for job in jobs]
    assert all(job.returncode == 0 for job in jobs), errors
    assert not any(errors), errors
    for j in range(40):
        manifest = json.loads((tmp_path / f"s{j}" / "manifest.json").read_text())
        assert manifest["kind"] == "sweep" and {"points.json", "point_0"} <= set(manifest["files"])
        assert all((tmp_path / f"s{j}" / f"point_{i}").is_dir() for i in range(4))


def test_job_array_of_four_concurrent_point_jobs_gives_the_serial_table(tmp_path, serial):
    out = tmp_path / "sweep"
    jobs = [subprocess.Popen(CLI + TINY + ["--point", str(i), "--out", str(out)],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=ENV)
            for i in (3, 1, 0, 2)]
    for job in jobs:
        stdout, stderr = job.communicate(timeout=300)
        assert job.returncode == 0, stderr
    assert_same_table(table(out), serial)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "completed" and summary["completed"] == 4
    manifest = json.loads((out / "manifest.json").read_text())
    assert set(manifest["files"]) == {"points.json", "summary.json", "sweep.csv", "sweep.png",
                                      "point_0", "point_1", "point_2", "point_3"}
    # a completed point is not run again; the table stays
    stamp = (out / "point_2" / "summary.json").stat().st_mtime_ns
    r = cli(*TINY, "--point", 2, "--out", out)
    assert r.returncode == 0 and (out / "point_2" / "summary.json").stat().st_mtime_ns == stamp
    assert_same_table(table(out), serial)


@pytest.mark.mpi
def test_a_point_job_on_two_ranks_joins_a_partial_sweep(tmp_path, serial):
    out = tmp_path / "sweep"
    assert cli(*TINY, "--max-points", 2, "--out", out).returncode == 0
    assert [r["status"] for r in table(out)] == ["completed"] * 2 + ["pending"] * 2
    r = cli(*TINY, "--point", 3, "--out", out, np_=2)
    assert r.returncode == 0, r.stderr
    assert [r["status"] for r in table(out)] == ["completed"] * 2 + ["pending", "completed"]
    assert json.loads((out / "point_3" / "summary.json").read_text())["mpi_size"] == 2
    assert cli(*TINY, "--point", 2, "--out", out).returncode == 0
    assert_same_table(table(out), serial)
    assert json.loads((out / "summary.json").read_text())["status"] == "completed"


@pytest.mark.parametrize("extra, expected", [
    (["--ranks-per-point", "2"], "2 ranks per point do not divide the 1 rank(s)"),
    (["--ranks-per-point", "0"], "--ranks-per-point must be a whole number >= 1"),
    (["--point", "4"], "point 4 is not in the grid: its 4 points are 0 to 3"),
    (["--point", "-1"], "point must be a whole number >= 0"),
    (["--point", "1", "--max-points", "1"], "exclude each other"),
])
def test_impossible_layouts_are_refused_before_any_work(tmp_path, extra, expected):
    out = tmp_path / "sweep"
    r = cli(*TINY, *extra, "--out", out)
    assert r.returncode == 2, (r.stdout, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and expected in lines[0], r.stderr
    assert not out.exists()


@pytest.mark.mpi
def test_ranks_per_point_not_dividing_the_ranks_is_refused_on_every_rank(tmp_path):
    out = tmp_path / "sweep"
    r = cli(*TINY, "--ranks-per-point", 3, "--out", out, np_=2)
    assert r.returncode == 2, r.stderr
    lines = tool_lines(r.stderr)
    assert len(lines) == 1 and "3 ranks per point do not divide the 2 rank(s)" in lines[0]
    assert not out.exists()


def test_a_point_job_into_the_folder_of_another_grid_is_refused(tmp_path):
    out = tmp_path / "sweep"
    assert cli(*TINY, "--point", 0, "--out", out).returncode == 0
    before = {p.name: p.stat().st_mtime_ns for p in out.rglob("*")}
    other = [a.replace("lam_u=500,1000", "lam_u=500,2000") for a in TINY]
    r = cli(*other, "--point", 1, "--out", out)
    assert r.returncode == 2 and "holds another sweep" in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1
    other = [a.replace("0.04", "0.05") for a in TINY]  # same grid, another T
    r = cli(*other, "--point", 1, "--out", out)
    assert r.returncode == 2 and "holds another sweep" in r.stderr, r.stderr
    assert {p.name: p.stat().st_mtime_ns for p in out.rglob("*")} == before


SCRIPT = textwrap.dedent('''
    import sys
    import ufl
    from dolfinx import fem
    from mpi4py import MPI
    import damage_dolfinx as dd
    from damage_dolfinx.geometries.rectangle import rectangle, side

    WHERE = sys.argv[2]
    calls = {"law": 0}

    def mesh(comm, n):
        return rectangle(comm, (0.0, 0.0), (2.0, 0.5), 4 * n, n,
                         {1: side(0, 0.0), 2: side(0, 2.0), 3: side(1, 0.0)})

    def law(eps, zeta, p):
        if WHERE == "group" and p.lam_u > 5e3:  # on every rank of the point's group
            raise ValueError("no law for this rate")
        # one rank, when a point's model is built on the live damage field (not in the checks,
        # which build the law on symbols alike on every rank)
        if WHERE == "rank" and MPI.COMM_WORLD.rank == 3 and isinstance(zeta, fem.Function):
            raise ZeroDivisionError("user law fails on rank 3")
        calls["law"] += 1  # the first call: the data's check; the second: the fingerprint
        if WHERE == "fingerprint" and MPI.COMM_WORLD.rank == 3 and calls["law"] == 2:
            raise ZeroDivisionError("user law fails on rank 3")
        return -p.lam_u * ufl.inner(eps, eps)

    problem = dd.Problem(model="2.2", mesh=mesh, n=3, T=0.03, k=0.01,
                         boundaries={"clamped": 1, "traction": 2, "tresca": 3},
                         traction=lambda x, t: ufl.as_vector((40.0 * t, 0.0)),
                         damage_law=dd.DamageLaw(law, "own"),
                         params={"E": 2000.0, "g_fric": 10.0})
    dd.sweep(problem, sys.argv[1], {"lam_u": [1e3, 1e4, 2e3, 3e3]}, ranks_per_point=2,
             figures=False, progress=False)
''')


def _script(tmp_path, where, timeout=120):
    script = tmp_path / "own.py"
    script.write_text(SCRIPT)
    out = tmp_path / "out"
    start = time.monotonic()
    proc = subprocess.run(["mpirun", "-n", "4", "--oversubscribe", sys.executable, str(script),
                           str(out), where], capture_output=True, text=True, env=ENV,
                          timeout=timeout)
    lines = tool_lines(proc.stderr)
    return proc, lines, out, time.monotonic() - start


@pytest.mark.mpi
def test_a_point_failing_on_its_whole_group_fails_alone(tmp_path):
    proc, lines, out, _ = _script(tmp_path, "group")
    assert proc.returncode == 0 and not lines, proc.stderr  # the API returns the summary
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed" and summary["failed"] == [1], summary
    assert "no law for this rate" in summary["errors"]["1"]
    rows = table(out)
    assert [r["status"] for r in rows] == ["completed", "failed", "completed", "completed"]


@pytest.mark.mpi
def test_a_failure_on_one_rank_of_a_group_ends_the_whole_sweep(tmp_path):
    proc, lines, out, seconds = _script(tmp_path, "rank")
    assert seconds < 60, (seconds, proc.stderr)
    assert proc.returncode in (2, 3), proc.stderr
    assert len(lines) == 1 and "rank 3" in lines[0], proc.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed", summary
    for folder in out.glob("point_*"):
        if (folder / "summary.json").exists():
            assert json.loads((folder / "summary.json").read_text())["status"] != "running"


@pytest.mark.mpi
def test_user_code_failing_on_one_rank_while_the_fingerprint_is_taken_is_refused_on_all(tmp_path):
    """The fingerprint runs the user's functions with no collective call in between and decides
    together: a refusal on every rank (exit 2, one line naming the rank), no abort, no folder."""
    proc, lines, out, seconds = _script(tmp_path, "fingerprint")
    assert seconds < 30, (seconds, proc.stderr)
    assert proc.returncode != 0 and "MPI_ABORT" not in proc.stderr, proc.stderr
    assert "fingerprint" in proc.stderr and "rank 3" in proc.stderr, proc.stderr
    assert not out.exists()


def test_a_refused_folder_receives_no_lock_file(tmp_path):
    out = tmp_path / "notes"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    r = cli(*TINY, "--point", 0, "--out", out)
    assert r.returncode == 2 and "notes.txt" in r.stderr, r.stderr
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]


def test_an_interrupted_point_job_leaves_an_honest_sweep_status(tmp_path):
    """SIGTERM to a job of one point: the point is "interrupted" and the sweep's status is
    rebuilt at once ("incomplete": no job is live any more), not left at "running"."""
    import signal
    out = tmp_path / "sweep"
    cmd = CLI + ["sweep", "2.2-ex1", "--n", "4", "--T", "50", "--k", "0.01", "--no-figures",
                 "--quiet", "--set", "kappa=0.01,0.1", "--point", "1", "--out", str(out)]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=ENV)
    deadline = time.monotonic() + 120
    history = out / "point_1" / "history.csv"
    while time.monotonic() < deadline and proc.poll() is None and \
            not (history.exists() and history.read_text().count("\n") > 3):
        time.sleep(0.1)  # the point's time loop is running
    proc.send_signal(signal.SIGTERM)
    _, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 143, stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "incomplete", summary
    assert summary["point_status"] == {"0": "pending", "1": "interrupted"}, summary
    assert [r["status"] for r in table(out)] == ["pending", "interrupted"]


def test_the_sweep_status_is_running_while_a_point_is_live_elsewhere(tmp_path):
    """The aggregate rebuilt while another job's point is live (its lock held by a living
    process) says "running" and names it; once that process is gone, "incomplete"."""
    from damage_dolfinx.studies.sweep_folder import settle
    out = tmp_path / "sweep"
    args = ["sweep", "2.2-ex1", "--n", "4", "--T", "0.02", "--k", "0.01", "--no-figures",
            "--quiet", "--set", "kappa=0.01,0.1", "--out", out]
    assert cli(*args, "--point", 0).returncode == 0
    mapping = json.loads((out / "points.json").read_text())
    other = out / "point_1"
    other.mkdir()
    (other / "summary.json").write_text('{"status": "running"}')
    live = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        import socket
        (other / ".lock").write_text(f"pid {live.pid} host {socket.gethostname()} since now\n")
        settle(out, mapping, 0, RuntimeError("a failure"), None, "2.2-ex1")
        summary = json.loads((out / "summary.json").read_text())
        assert summary["status"] == "running" and summary["live"] == [1], summary
    finally:
        live.kill()
        live.wait()
    settle(out, mapping, 0, RuntimeError("a failure"), None, "2.2-ex1")
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "incomplete" and summary["live"] == [], summary
    assert summary["point_status"]["0"] == "completed"


def test_a_mesh_size_the_geometry_refuses_is_refused_before_any_point(tmp_path):
    out = tmp_path / "sweep"
    r = cli("sweep", "2.1-ex1", "--n", "7", "--T", "0.02", "--set", "kappa=0.5,1",
            "--no-figures", "--quiet", "--out", out)
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    # the sweep's own n is wrong, whatever the point: said without naming a point
    assert len(lines) == 1 and "point" not in lines[0] and "multiple of 5" in lines[0], r.stderr
    assert not out.exists()
    r = cli("sweep", "2.1-ex1", "--n", "5", "--T", "0.02", "--set", "kappa=0.5,-1",
            "--no-figures", "--quiet", "--out", out)
    assert r.returncode == 2 and "point 1 (kappa = -1)" in r.stderr, r.stderr
    assert not out.exists()
