"""Faults a run survives (the full table: benchmarks/faults/faults.py): restarts of finished
runs, corrupted checkpoints, a full disk (here a file-size limit, no root needed), signals, a
double run. Every fault ends with one line and a documented exit status, nothing finished is
lost, and resumed runs equal the uninterrupted run to 1e-12."""
import builtins
import errno
import json
import os
import resource
import shutil
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from conftest import ENV, load_run, rel_diff, run_cli, tool_lines
from damage_dolfinx.runtime import atomic, io
from damage_dolfinx import cli

RUN = ["run", "2.4-ex1", "--n", "8", "--k", "0.01", "--T", "0.6", "--no-figures", "--quiet"]
#: long enough (1500 steps) to be stopped by a signal while it runs
LONG = ["run", "2.4-ex1", "--n", "8", "--k", "0.001", "--T", "1.5", "--no-figures", "--quiet"]


def _main(args, out, capsys):
    """cli.main in this process (no start-up cost): (exit status, stdout, stderr)."""
    status = cli.main([*map(str, args), "--out", str(out)])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def _max_diff(a, b):
    _, fa = load_run(a)
    _, fb = load_run(b)
    return max(rel_diff(fa[k], fb[k]) for k in fb if not k.endswith("_coords"))


def _wait_for_step(out, step, proc, timeout=900):
    """Until history.csv has reached ``step`` (returns at once then; a loaded machine only
    makes it wait longer), the process ended, or ``timeout`` s."""
    deadline = time.time() + timeout
    while time.time() < deadline and proc.poll() is None:
        rows = io.CSVHistory.read_rows(out / "history.csv", 10 ** 9)
        if rows and int(rows[-1]["step"]) >= step:
            return
        time.sleep(0.01)
    raise AssertionError(f"no step {step} within {timeout} s")


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    out = tmp_path_factory.mktemp("reference")
    run_cli(RUN + ["--out", out])
    return out


def test_restart_of_a_completed_run_and_run_into_it(tmp_path, capsys, reference):
    done = tmp_path / "done"
    assert _main(RUN, done, capsys)[0] == 0
    files = {f: (done / f).read_bytes() for f in ("summary.json", "history.csv",
                                                  "fields_final.npz")}
    status, out, err = _main(RUN + ["--restart"], done, capsys)
    assert status == 0 and "nothing to do" in out and "completed" in out
    assert all((done / f).read_bytes() == data for f, data in files.items())
    status, out, err = _main(RUN, done, capsys)  # no --restart, no --overwrite: refused
    assert status == 2 and "holds a finished run" in err and err.count("\n") == 1
    assert all((done / f).read_bytes() == data for f, data in files.items())
    # a larger T continues from the final checkpoint: same as a run straight to that T
    longer = RUN[:-4] + ["--T", "0.8", "--no-figures", "--quiet"]
    assert _main(longer + ["--restart"], done, capsys)[0] == 0
    straight = tmp_path / "straight"
    assert _main(longer, straight, capsys)[0] == 0
    summary = json.loads((done / "summary.json").read_text())
    assert summary["status"] == "completed" and summary["restarts"][0]["step"] == 60
    assert _max_diff(done, straight) < 1e-12
    assert len((done / "history.csv").read_text().splitlines()) == 1 + 80 + 1
    assert _main(RUN + ["--overwrite"], done, capsys)[0] == 0
    assert _max_diff(done, reference) < 1e-12


@pytest.mark.parametrize("damage", ["truncated", "zero-length"])
def test_unreadable_checkpoint_falls_back_to_the_previous(tmp_path, capsys, reference, damage):
    out = tmp_path / "run"
    assert _main(RUN[:-4] + ["--T", "0.4", "--no-figures", "--quiet", "--checkpoint-every",
                             "10"], out, capsys)[0] == 0  # generations at steps 40 and 30
    path = out / "checkpoint.npz"
    with open(path, "r+b") as f:
        f.truncate(path.stat().st_size // 2 if damage == "truncated" else 0)
    status, _, err = _main(RUN + ["--checkpoint-every", "10", "--restart"], out, capsys)
    assert status == 0 and "checkpoint.npz is unreadable" in err
    assert "restarting from checkpoint.prev.npz (step 30)" in err and "Traceback" not in err
    assert _max_diff(out, reference) < 1e-12


def test_no_readable_checkpoint_is_refused(tmp_path, capsys):
    out = tmp_path / "run"
    out.mkdir()
    (out / "checkpoint.npz").write_bytes(b"")
    status, _, err = _main(RUN + ["--restart"], out, capsys)
    assert status == 2 and "no readable checkpoint" in err and err.count("\n") == 1


#: the command line under a file-size limit (set after MPI_Init, whose shared-memory files it
#: would break): writes beyond it fail with EFBIG, as a full disk fails with ENOSPC
LIMITED = """import signal, resource, sys
from mpi4py import MPI
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, (int(sys.argv[1]), resource.RLIM_INFINITY))
from damage_dolfinx.cli import main
sys.exit(main(sys.argv[2:]))
"""


def test_output_error_stops_the_run_and_restart_continues(tmp_path, reference):
    """A write failing mid-run (fields.h5 reaches a 120 kB file-size limit): exit status 4,
    one line naming file and step, summary.json 'failed', the finished steps kept; --restart
    without the limit ends equal to the uninterrupted run."""
    out = tmp_path / "run"
    cmd = [sys.executable, "-c", LIMITED, "120000", *RUN, "--checkpoint-every", "10",
           "--write-every", "3", "--out", str(out)]
    proc = subprocess.run(cmd, env=ENV, capture_output=True, text=True)
    assert proc.returncode == 4, proc.stderr
    line = proc.stderr.strip()
    assert line.count("\n") == 0 and "Traceback" not in line
    assert line.startswith("damage-dolfinx: output error: cannot write fields.xdmf (+ .h5) at "
                           "step "), line
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed" and summary["error"] in line
    step = summary["steps_done"]
    rows = io.CSVHistory.read_rows(out / "history.csv", 10 ** 9)
    assert int(rows[-1]["step"]) == step and 0 < step < 60
    run_cli(RUN + ["--checkpoint-every", "10", "--write-every", "3", "--restart", "--out", out])
    assert _max_diff(out, reference) < 1e-12


class _FailingDisk:
    """Fault injection: the files whose name starts with ``name`` (their temporary files too)
    that the output modules open get writes that fail with EIO (a failing disk) from the
    ``after``-th write on, counted over all of them."""

    def __init__(self, monkeypatch, name, after):
        self.name, self.after, self.writes = name, after, 0
        for module in (atomic, io):
            monkeypatch.setattr(module, "open", self.open, raising=False)

    def open(self, path, mode="r", *args, **kwargs):
        f = builtins.open(path, mode, *args, **kwargs)
        return _FailingFile(f, self) if os.path.basename(path).startswith(self.name) else f


class _FailingFile:
    def __init__(self, f, disk):
        self._f, self._disk = f, disk

    def write(self, data):
        self._disk.writes += 1
        if self._disk.writes >= self._disk.after:
            raise OSError(errno.EIO, os.strerror(errno.EIO))
        return self._f.write(data)

    def __getattr__(self, name):
        return getattr(self._f, name)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self._f.close()


@pytest.mark.parametrize("name, after", [("history.csv", 25), ("checkpoint.npz", 3),
                                         ("summary.json", 12)])
def test_io_error_stops_the_run_and_restart_continues(tmp_path, capsys, monkeypatch, reference,
                                                      name, after):
    """EIO (injected) in the history, a checkpoint or the summary: exit status 4, one line
    naming file and step; the finished steps and the last complete checkpoint stay, and
    --restart (the disk repaired) ends equal to the uninterrupted run."""
    out = tmp_path / "run"
    with monkeypatch.context() as patch:
        _FailingDisk(patch, name, after)
        status, _, err = _main(RUN + ["--checkpoint-every", "10"], out, capsys)
    assert status == 4 and err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith(f"damage-dolfinx: output error: cannot write {name} at step "), err
    assert err.rstrip().endswith(": Input/output error"), err
    print(err.strip())
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed"  # a failing summary write: rewritten in its own space
    assert not list(out.glob("*.tmp"))
    status, _, err = _main(RUN + ["--checkpoint-every", "10", "--restart"], out, capsys)
    assert status == 0, err
    assert _max_diff(out, reference) < 1e-12


@pytest.mark.parametrize("np_", [1, pytest.param(2, marks=pytest.mark.mpi)])
def test_output_folder_deleted_mid_run(tmp_path, np_):
    """The output folder removed while the run writes into it: one line, exit status 4."""
    out = tmp_path / "run"
    cmd = [sys.executable, "-m", "damage_dolfinx.cli", *LONG, "--write-every", "10",
           "--out", str(out)]
    if np_ > 1:
        cmd = ["mpirun", "-n", str(np_), *cmd]
    proc = subprocess.Popen(cmd, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    _wait_for_step(out, 20, proc)
    while out.exists():  # files may appear while the tree is removed
        shutil.rmtree(out, ignore_errors=True)
    _, err = proc.communicate(timeout=900)  # the next write fails: seconds, more when loaded
    assert proc.returncode == 4, err
    ours = tool_lines(err)
    assert len(ours) == 1 and "Traceback" not in err, err
    # the reason: the file or folder missing; or, when the write falls inside the removal (its
    # file already gone, the folder not yet), HDF5's own failure to open the file it appends to
    assert ours[0].startswith("damage-dolfinx: output error: cannot write ") and \
        " at step " in ours[0] and ("No such file or directory" in ours[0] or
                                    ours[0].endswith(" (the output folder is gone)") or
                                    ours[0].endswith("Failed to create/open HDF5 file "
                                                     "(append mode)")), ours[0]
    print(ours[0])


@pytest.mark.parametrize("sig, np_", [(signal.SIGTERM, 1), (signal.SIGINT, 1),
                                      pytest.param(signal.SIGTERM, 2, marks=pytest.mark.mpi)])
def test_signal_writes_a_checkpoint_and_marks_the_summary(tmp_path, sig, np_):
    """SIGTERM/SIGINT (to the process, or to every rank as a batch scheduler does), sent twice
    in a row: a checkpoint at the end of the current step, status 'interrupted', exit status
    128 + sig."""
    out = tmp_path / "run"
    cmd = [sys.executable, "-m", "damage_dolfinx.cli", *LONG, "--out", str(out)]
    if np_ > 1:
        cmd = ["mpirun", "-n", str(np_), *cmd]
    proc = subprocess.Popen(cmd, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True)
    _wait_for_step(out, 50, proc)
    ranks = subprocess.run(["pgrep", "-s", str(proc.pid), "-f", "damage_dolfinx.cli"],
                           capture_output=True, text=True).stdout.split()
    for _ in range(2):  # the same request twice (scheduler + mpirun): still a clean stop
        for pid in ranks if np_ > 1 else [proc.pid]:
            if np_ == 1 or int(pid) != proc.pid:
                os.kill(int(pid), sig)
        time.sleep(0.05)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 128 + sig, err
    ours = tool_lines(err)
    assert len(ours) == 1 and f"stopped by {signal.Signals(sig).name} after step" in ours[0]
    assert "Traceback" not in err
    summary = json.loads((out / "summary.json").read_text())
    meta = json.loads((out / "checkpoint.json").read_text())
    assert summary["status"] == "interrupted" and summary["signal"] == signal.Signals(sig).name
    assert meta["step"] == summary["steps_done"] < 1500
    assert not (out / ".lock").exists()


def test_double_run_is_refused_and_a_dead_runs_lock_does_not_block(tmp_path, capsys):
    out = tmp_path / "run"
    cmd = [sys.executable, "-m", "damage_dolfinx.cli", *LONG, "--checkpoint-every", "20",
           "--out", str(out)]
    proc = subprocess.Popen(cmd, env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        _wait_for_step(out, 30, proc)
        status, _, err = _main(LONG + ["--overwrite"], out, capsys)
        assert status == 2 and "a run is live in" in err and f"pid {proc.pid}" in err
    finally:
        proc.kill()
        proc.wait()
    assert (out / ".lock").exists()  # SIGKILL: the file stays, its lock died with the process
    status, _, err = _main(LONG + ["--checkpoint-every", "20", "--restart"], out, capsys)
    assert status == 0, err
    assert json.loads((out / "summary.json").read_text())["status"] == "completed"


@pytest.mark.parametrize("refactor_its", [None, 4])
def test_lagged_factorisation_is_restored_on_restart(tmp_path, capsys, monkeypatch,
                                                     refactor_its):
    """2.1 solves its elasticity by CG preconditioned with the factorisation of an earlier
    step's matrix; the checkpoint holds that step's damage, so restarts end bitwise equal to
    the uninterrupted run (the factorisation rebuilt from the current damage instead: 5.6e-13
    with the default lag, one factorisation in the run; 5.7e-14 with refactorisations after
    4 CG iterations, 6 in the run, here 4 restarts)."""
    from damage_dolfinx.models import elastic_2_1
    if refactor_its:
        monkeypatch.setattr(elastic_2_1, "MECH_REFACTOR_ITS", refactor_its)
    base = ["run", "2.1-ex1", "--n", "5", "--k", "0.01", "--no-figures", "--quiet",
            "--checkpoint-every", "7"]
    assert _main(base + ["--T", "1"], tmp_path / "ref", capsys)[0] == 0
    stops = ("0.33", "0.5", "0.71", "0.9", "1") if refactor_its else ("0.33", "0.71", "1")
    for i, T in enumerate(stops):
        again = ["--restart"] if i else []
        assert _main(base + ["--T", T, *again], tmp_path / "part", capsys)[0] == 0
    factorizations = json.loads((tmp_path / "ref" / "summary.json").read_text())[
        "iterations"]["mech_factorizations"]
    assert (factorizations > 2) if refactor_its else (factorizations < 3)
    assert _max_diff(tmp_path / "part", tmp_path / "ref") == 0.0


def test_history_restart_drops_a_row_cut_by_a_full_disk(tmp_path):
    path = tmp_path / "history.csv"
    path.write_text("step,t,x\n0,0.0,1\n1,0.1,2\n2,0.2,3\n3,0.3")  # row 3 cut mid-way
    rows = io.CSVHistory.read_rows(path, 10)
    assert [r["step"] for r in rows] == ["0", "1", "2"]
    assert [r["step"] for r in io.CSVHistory.read_rows(path, 1)] == ["0", "1"]


def test_xdmf_killed_mid_write_is_restored_from_its_copy(tmp_path):
    """DOLFINx rewrites the XDMF XML in place; io.XDMFSeries keeps a copy while it does."""
    good = '<?xml version="1.0"?>\n<Xdmf><Domain><Grid Name="mesh"/></Domain></Xdmf>\n'
    (tmp_path / "fields.xdmf").write_text(good[:40])  # killed mid-write
    (tmp_path / "fields.xdmf.bak").write_text(good)
    (tmp_path / "other.xdmf").write_text(good)  # a finished write whose copy was left
    (tmp_path / "other.xdmf.bak").write_text(good)
    assert io.repair_xdmf(tmp_path) == ["fields.xdmf"]
    assert (tmp_path / "fields.xdmf").read_text() == good
    assert not list(tmp_path.glob("*.bak"))


# ---------------------------------------------------------------------------- a full disk
@pytest.fixture
def small_disk(tmp_path):
    """A 64 MB tmpfs (root only: skipped elsewhere) whose space ``fill()`` takes, at the moment
    a test chooses, until a write fails with ENOSPC; ``free()`` gives it back."""
    mount = tmp_path / "disk"
    mount.mkdir()
    proc = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64m", "tmpfs", str(mount)],
                          capture_output=True, text=True)
    if proc.returncode != 0:
        pytest.skip(f"no tmpfs mount here: {proc.stderr.strip()}")

    class Disk:
        path = mount
        filler = mount / "filler"

        def fill(self):
            block = b"\0" * (1 << 16)
            with open(self.filler, "ab") as f:
                try:
                    while True:
                        f.write(block)
                        f.flush()
                except OSError as exc:
                    assert exc.errno == errno.ENOSPC
            try:  # the last bytes too (a tmpfs counts pages)
                with open(self.filler.with_suffix(".tail"), "ab") as f:
                    while True:
                        f.write(b"\0")
                        f.flush()
            except OSError:
                pass

        def free(self):
            for f in (self.filler, self.filler.with_suffix(".tail")):
                f.unlink(missing_ok=True)
    try:
        yield Disk()
    finally:
        subprocess.run(["umount", "-l", str(mount)], capture_output=True)


def _full_then(disk, real):
    """``real``, called when the disk has just become full."""
    def call(*args, **kwargs):
        disk.fill()
        return real(*args, **kwargs)
    return call


def _one_line(err, start):
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1 and "Traceback" not in err, err
    assert lines[0].startswith(start), lines[0]
    return lines[0]


CONVERGE = ["converge", "2.1-ex1", "--ref-n", "20", "--n", "5", "10", "--ref-k", "0.01", "--k",
            "0.02", "--T", "0.04", "--quiet"]


def test_full_disk_at_the_convergence_plot(small_disk, capsys, monkeypatch):
    """The disk fills while converge draws convergence.png: exit status 4, one line naming the
    file, summary.json 'failed' (the lock's reserve takes it); the space freed, --restart runs
    the study again and completes."""
    from damage_dolfinx.studies import convergence
    out = small_disk.path / "study"
    with monkeypatch.context() as patch:
        patch.setattr(convergence, "plot_convergence",
                      _full_then(small_disk, convergence.plot_convergence))
        status, _, err = _main(CONVERGE, out, capsys)
    assert status == 4, err
    line = _one_line(err, "damage-dolfinx: output error: cannot write ")
    assert "convergence.png" in line and "No space left on device" in line, line
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed" and "convergence.png" in summary["error"]
    small_disk.free()
    status, _, err = _main(CONVERGE + ["--restart"], out, capsys)
    assert status == 0, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "completed" and len(summary["errors"]) == 2
    assert (out / "convergence.png").stat().st_size > 0


def test_full_disk_at_a_runs_figures(small_disk, capsys, monkeypatch):
    """The disk fills while a run draws its figures: exit status 4, one line naming the
    figure, summary.json 'failed' with every step done; the space freed, --restart finishes
    the figures and the summary says 'completed' with all steps, t_final and final scalars."""
    from damage_dolfinx.runtime import records
    out = small_disk.path / "run"
    args = ["run", "2.1-ex1", "--n", "5", "--k", "0.01", "--T", "0.05", "--quiet",
            "--checkpoint-every", "5"]
    with monkeypatch.context() as patch:
        patch.setattr(records, "draw_figure", _full_then(small_disk, records.draw_figure))
        status, _, err = _main(args, out, capsys)
    assert status == 4, err
    line = _one_line(err, "damage-dolfinx: output error: cannot write ")
    assert ".png" in line and "No space left on device" in line, line
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed" and summary["steps_done"] == 5
    small_disk.free()
    status, _, err = _main(args + ["--restart"], out, capsys)
    assert status == 0, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "completed" and summary["steps_done"] == 5
    assert summary["t_final"] == pytest.approx(0.05) and summary["final"]
    assert all((out / f["file"]).stat().st_size > 0 for f in summary["outputs"]["figures"])


def test_full_disk_at_sweep_csv(small_disk, capsys, monkeypatch):
    """The disk fills as sweep.csv is written: exit status 4, one line naming sweep.csv, the
    sweep's summary 'failed'; the space freed, --restart writes the table of both points."""
    out = small_disk.path / "sweep"
    args = ["sweep", "2.1-ex1", "--set", "kappa=0.5,1", "--n", "5", "--T", "0.02",
            "--no-figures", "--quiet"]
    real = io.atomic_write_bytes

    def write(path, *a, **kw):
        if os.path.basename(path) == "sweep.csv":
            small_disk.fill()
        return real(path, *a, **kw)
    with monkeypatch.context() as patch:
        patch.setattr(io, "atomic_write_bytes", write)
        status, _, err = _main(args, out, capsys)
    assert status == 4, err
    line = _one_line(err, "damage-dolfinx: output error: cannot write ")
    assert "sweep.csv" in line and "No space left on device" in line, line
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed", summary
    small_disk.free()
    status, _, err = _main(args + ["--restart"], out, capsys)
    assert status == 0, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "completed" and summary["completed"] == 2
    assert len((out / "sweep.csv").read_text().splitlines()) == 3
