"""Checkpoint/restart: a run killed mid-way resumes from its last checkpoint (on another number
of ranks) and ends with the same fields as an uninterrupted run; bad restarts are refused."""
import json
import os
import signal
import subprocess
import sys
import time

from conftest import ENV, load_run, rel_diff, run_cli

ARGS = ["run", "2.4-ex1", "--n", "8", "--k", "0.005", "--T", "2", "--no-figures", "--quiet"]


def _killed_two_rank_run(out, min_step=40):
    """Start ARGS on 2 ranks with a checkpoint every 10 steps; SIGKILL the whole job once a
    checkpoint at step >= min_step exists. Returns the step of the last checkpoint written."""
    cmd = ["mpirun", "-n", "2", sys.executable, "-m", "damage_dolfinx.cli", *ARGS,
           "--checkpoint-every", "10", "--out", str(out)]
    proc = subprocess.Popen(cmd, env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)
    meta, deadline = out / "checkpoint.json", time.time() + 300
    try:
        while time.time() < deadline and proc.poll() is None:
            if meta.is_file() and json.loads(meta.read_text())["step"] >= min_step:
                # the whole session: mpirun and its ranks (which OpenMPI may regroup)
                subprocess.run(["pkill", "-KILL", "-s", str(proc.pid)], check=False)
                try:
                    os.killpg(proc.pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
                break
            time.sleep(0.02)
    finally:
        proc.wait()
        # ranks that Open MPI started outside mpirun's session (Open MPI 6's daemons) may outlive
        # it for a moment and still write a checkpoint: kill them by their run folder, and wait
        # until none is left before the checkpoint on disk is read
        subprocess.run(["pkill", "-KILL", "-f", str(out)], check=False)
        gone = time.time() + 30
        while time.time() < gone and subprocess.run(["pgrep", "-f", str(out)],
                                                     capture_output=True).returncode == 0:
            time.sleep(0.05)
    assert proc.returncode != 0, "the run finished before it could be killed"
    return json.loads(meta.read_text())["step"]


def test_killed_run_resumes_on_other_rank_count(tmp_path):
    run_cli(ARGS + ["--out", tmp_path / "full"])
    step = _killed_two_rank_run(tmp_path / "part")
    summary, _ = load_run(tmp_path / "full")
    partial = json.loads((tmp_path / "part" / "summary.json").read_text())
    assert partial["status"] == "running" and partial["steps_done"] >= step
    run_cli(ARGS + ["--restart", "--out", tmp_path / "part"])  # serial this time
    resumed, fields = load_run(tmp_path / "part")
    _, reference = load_run(tmp_path / "full")
    assert resumed["status"] == "completed" and resumed["restarts"][0]["step"] == step
    assert resumed["restarts"][0]["previous_mpi_size"] == 2
    for name in ("u", "zeta", "sigma", "von_mises"):
        diff = rel_diff(fields[name], reference[name])
        print(f"{name}: resumed (killed at step {step}, 2 -> 1 ranks) vs uninterrupted {diff:.1e}")
        assert diff < 1e-10, name
    rows = (tmp_path / "part" / "history.csv").read_text().splitlines()
    assert len(rows) == 1 + summary["num_steps"] + 1  # header, steps 0..N, no duplicates


def test_restart_is_refused_without_or_with_a_foreign_checkpoint(tmp_path):
    proc = run_cli(ARGS + ["--restart", "--out", tmp_path], check=False)
    assert proc.returncode == 2 and "no checkpoint" in proc.stderr
    run_cli(ARGS[:-4] + ["--T", "0.05", "--no-figures", "--quiet", "--checkpoint-every", "5",
                         "--out", tmp_path])
    proc = run_cli(["run", "2.4-ex1", "--n", "16", "--k", "0.005", "--restart", "--quiet",
                    "--out", tmp_path], check=False)
    assert proc.returncode == 2 and "n = 8" in proc.stderr
