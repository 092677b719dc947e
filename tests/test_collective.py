"""One decided outcome on every rank: an exception raised on one rank only (user code, or our
own refusal) ends every rank within seconds, with one line, a status and one exit status."""
import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from conftest import ENV, tool_lines

SCRIPT = textwrap.dedent('''
    import sys
    import ufl
    from mpi4py import MPI
    import damage_dolfinx as dd
    from damage_dolfinx.geometries.rectangle import rectangle, side

    WHERE = sys.argv[2]
    calls = {"law": 0, "traction": 0}

    def mesh(comm, n):
        return rectangle(comm, (0.0, 0.0), (2.0, 0.5), 4 * n, n,
                         {1: side(0, 0.0), 2: side(0, 2.0), 3: side(1, 0.0)})

    def traction(x, t):
        calls["traction"] += 1  # (the first call: the data's check, alike on every rank)
        if WHERE == "traction" and MPI.COMM_WORLD.rank == 1 and calls["traction"] > 1:
            raise RuntimeError("user load fails on rank 1")
        return ufl.as_vector((40.0 * t, 0.0))

    def law(eps, zeta, p):
        calls["law"] += 1
        if WHERE == "law" and MPI.COMM_WORLD.rank == 1 and calls["law"] > 1:
            raise ZeroDivisionError("user law fails on rank 1")
        return -100.0 * ufl.inner(eps, eps)

    problem = dd.Problem(model="2.2", mesh=mesh, n=4, T=0.05,
                         boundaries={"clamped": 1, "traction": 2, "tresca": 3},
                         traction=traction, damage_law=dd.DamageLaw(law, "own"),
                         params={"E": 2000.0, "g_fric": 10.0})
    try:
        dd.run(problem, sys.argv[1], figures=False, progress=False)
    except dd.InputError as exc:  # a refusal decided on every rank alike (the script's line)
        if MPI.COMM_WORLD.rank == 0:
            print(f"damage-dolfinx: error: {exc}", file=sys.stderr)
        sys.exit(2)
''')


def _mpirun(n, args, timeout=60):
    cmd = ["mpirun", "-n", str(n)] + (["--oversubscribe"] if n > 2 else []) + args
    start = time.monotonic()
    proc = subprocess.run(cmd, capture_output=True, text=True, env=ENV, timeout=timeout)
    return proc, time.monotonic() - start


@pytest.mark.parametrize("ranks", [2, 3])
@pytest.mark.parametrize("where", ["traction", "law"])
def test_user_code_failing_on_rank_1_only_ends_every_rank(tmp_path, ranks, where):
    script = tmp_path / "own.py"
    script.write_text(SCRIPT)
    out = tmp_path / "out"
    proc, seconds = _mpirun(ranks, [sys.executable, str(script), str(out), where])
    assert seconds < 30, (seconds, proc.stderr)
    assert proc.returncode in (2, 3), proc.stderr
    lines = tool_lines(proc.stderr)
    assert len(lines) == 1 and "rank 1" in lines[0], proc.stderr
    assert "Traceback" not in proc.stderr
    if (out / "summary.json").exists():
        assert json.loads((out / "summary.json").read_text())["status"] != "running"


def test_sweep_refusal_on_one_point_is_collective(tmp_path):
    out = tmp_path / "sm"
    (out / "point_1").mkdir(parents=True)
    (out / "point_1" / "notes.txt").write_text("mine")
    proc, seconds = _mpirun(2, [sys.executable, "-m", "damage_dolfinx.cli", "sweep", "2.1-ex1",
                                "--set", "kappa=0.5,1", "--n", "5", "--T", "0.02", "--out",
                                str(out), "--no-figures", "--quiet"])
    assert seconds < 30 and proc.returncode == 2, proc.stderr
    lines = tool_lines(proc.stderr)
    assert len(lines) == 1 and "point_1" in lines[0], proc.stderr
    assert (out / "point_1" / "notes.txt").read_text() == "mine"
    assert not (out / "point_0").exists()


def test_sigterm_to_one_rank_of_a_sweep_ends_every_rank(tmp_path):
    out = tmp_path / "sw"
    # each point runs for seconds (about 8000 steps before zeta* is reached), so that rank 0's
    # point is still running when rank 1's notice comes: at k = 0.01 it ended in 0.3 s, at
    # times before the notice (it is then "completed", as it should be)
    cmd = ["mpirun", "-n", "2", sys.executable, "-m", "damage_dolfinx.cli", "sweep", "2.1-ex1",
           "--set", "kappa=0.5,1", "--set", "lam_u_plus=1", "--n", "10", "--T", "5",
           "--k", "0.0005", "--out", str(out),
           "--no-figures"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=ENV)
    deadline = time.monotonic() + 120
    pid = None
    while time.monotonic() < deadline and pid is None and proc.poll() is None:
        time.sleep(0.2)  # rank 1's point has started
        if (out / "point_1" / "summary.json").exists():
            pid = _rank_pid(proc.pid, 1)
    if pid is None:
        proc.kill()
        stdout, stderr = proc.communicate()
    assert pid, f"point 1 never started: {stdout}{stderr}"
    os.kill(pid, signal.SIGTERM)
    sent = time.monotonic()
    stdout, stderr = proc.communicate(timeout=60)
    assert time.monotonic() - sent < 30
    assert proc.returncode == 143, stderr
    status = json.loads((out / "summary.json").read_text())["status"]
    assert status == "interrupted", status
    # the signal is passed on: the other rank's point stops at the end of its step too, with
    # its checkpoint, and every rank ends normally (no abort, nothing of mpirun's own)
    for i in (0, 1):
        assert json.loads((out / f"point_{i}" / "summary.json").read_text())["status"] == \
            "interrupted"
    lines = tool_lines(stderr)
    assert len(lines) == 1 and "SIGTERM" in lines[0], stderr
    assert "MPI_ABORT" not in stderr and "job aborted" not in stderr, stderr


def _rank_pid(mpirun_pid, rank):
    """The pid of the given rank (OMPI_COMM_WORLD_RANK in its environment)."""
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            env = (entry / "environ").read_bytes().split(b"\0")
        except OSError:
            continue
        if f"OMPI_COMM_WORLD_RANK={rank}".encode() in env and \
                f"damage_dolfinx.cli".encode() in (entry / "cmdline").read_bytes():
            return int(entry.name)
    return None
