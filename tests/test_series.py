"""What a researcher reads back: one fields.xdmf series per run across kills and restarts on
1 -> 2 -> 3 ranks (read with h5py through read_run), and read_run on 2 ranks = serial."""
import json
import os
import signal
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

import numpy as np

from conftest import ENV, rel_diff, run_cli

ARGS = ["run", "2.4-ex1", "--n", "8", "--k", "0.005", "--T", "1", "--no-figures", "--quiet",
        "--write-every", "5"]


def _killed_run(out, np_, min_step, extra=()):
    """Start ARGS (+ extra) on np_ ranks with a checkpoint every 40 steps; SIGKILL the whole job
    once the summary reports a step >= min_step past the last checkpoint (outputs beyond it).
    Returns the step of the last checkpoint."""
    cmd = [sys.executable, "-m", "damage_dolfinx.cli", *ARGS, *extra, "--checkpoint-every", "40",
           "--out", str(out)]
    if np_ > 1:
        cmd = ["mpirun", "-n", str(np_), *cmd]
    proc = subprocess.Popen(cmd, env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)
    deadline = time.time() + 300
    try:
        while time.time() < deadline and proc.poll() is None:
            try:
                done = json.loads((out / "summary.json").read_text())["steps_done"]
            except (OSError, ValueError, KeyError):
                done = 0
            try:  # outputs past the last checkpoint: times the restart writes again
                saved = json.loads((out / "checkpoint.json").read_text())["step"]
            except (OSError, ValueError, KeyError):
                saved = done
            if done >= min_step and 5 <= done - saved <= 10:  # far from the next checkpoint
                subprocess.run(["pkill", "-KILL", "-s", str(proc.pid)], check=False)
                try:
                    os.killpg(proc.pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
                break
            time.sleep(0.01)
    finally:
        proc.wait()
    assert proc.returncode != 0, "the run finished before it could be killed"
    return json.loads((out / "checkpoint.json").read_text())["step"]


def _last_time(path):
    """The last time an XDMF file holds (its copy if the kill cut its XML)."""
    for candidate in (path, path.with_name(path.name + ".bak")):
        try:
            return max(float(e.get("Value")) for e in ET.parse(candidate).getroot().iter("Time"))
        except (OSError, ET.ParseError):
            pass
    raise AssertionError(f"{path.name} unreadable")


def test_killed_twice_on_1_2_3_ranks_reads_back_as_one_series(tmp_path):
    import damage_dolfinx as dd
    full, part = tmp_path / "full", tmp_path / "part"
    run_cli(ARGS + ["--out", full])
    first = _killed_run(part, 1, 73)
    before = _last_time(part / "fields.xdmf")  # the first run's own series
    second = _killed_run(part, 2, 147, ["--restart"])
    overlaps = [before, _last_time(part / "fields.xdmf")]  # now the index of both segments
    print(f"the killed runs had written up to t = {overlaps[0]:g} and {overlaps[1]:g}; "
          f"restarted from t = {first * 0.005:g} and {second * 0.005:g}")
    assert overlaps[0] > first * 0.005 and overlaps[1] > second * 0.005  # times written twice
    run_cli(ARGS + ["--restart", "--out", part], np_=3)
    run, reference = dd.read_run(part), dd.read_run(full)
    summary = run.summary
    assert [r["step"] for r in summary["restarts"]] == [first, second]
    assert [r["mpi_size"] for r in summary["restarts"]] == [2, 3]
    assert summary["outputs"]["xdmf"] == "fields.xdmf"
    assert summary["outputs"]["xdmf_data"] == ["fields.h5", f"fields_from_step{first}.h5",
                                               f"fields_from_step{second}.h5"]
    times = run.times
    print(f"killed at checkpoints {first} (1 rank) and {second} (2 ranks), finished on 3 ranks: "
          f"fields.xdmf holds {len(times)} times from {times[0]:g} to {times[-1]:g}")
    assert np.all(np.diff(times) > 0) and times[0] == 0.0 and np.isclose(times[-1], 1.0)
    assert np.allclose(times, reference.times, rtol=0, atol=1e-12)
    steps = [float(g.get("Value")) for g in ET.parse(part / "fields.xdmf").getroot().iter(
        "Time")]
    assert len(steps) == len(times)  # one grid per time, holding every field
    for name in reference.names:  # every field at every time
        for t in (times[0], times[len(times) // 2], times[-1]):
            diff = rel_diff(run.field(name, t).values, reference.field(name, t).values)
            assert diff < 1e-10, (name, t, diff)
        last = run.field(name)
        assert np.allclose(last.coords, reference.final[name + "_coords"], atol=1e-12)
        diff = rel_diff(last.values, reference.final[name])
        print(f"{name} at t = {last.t:g}: killed twice and resumed vs uninterrupted {diff:.1e}")
        assert diff < 1e-10, name
    assert np.array_equal(run.history["step"], np.arange(summary["num_steps"] + 1))


def test_read_run_on_two_ranks_equals_serial(tmp_path):
    import damage_dolfinx as dd
    args = ["run", "2.4-ex1", "--n", "6", "--k", "0.01", "--T", "0.3", "--no-figures", "--quiet"]
    run_cli(args + ["--out", tmp_path / "s"])
    run_cli(args + ["--out", tmp_path / "p"], np_=2)
    serial, parallel = dd.read_run(tmp_path / "s"), dd.read_run(tmp_path / "p")
    assert serial.summary["mpi_size"] == 1 and parallel.summary["mpi_size"] == 2
    assert np.array_equal(serial.times, parallel.times) and serial.names == parallel.names
    for name in serial.names:
        for t in serial.times:
            a, b = serial.field(name, t), parallel.field(name, t)
            assert np.allclose(a.coords, b.coords, atol=1e-12)
            assert rel_diff(b.values, a.values) < 1e-8, (name, t)
        print(f"{name}: 2 ranks vs serial at t = {t:g}: {rel_diff(b.values, a.values):.1e}")
    for column in ("t", "u_L2", "zeta_min"):
        assert np.allclose(serial.history[column], parallel.history[column], rtol=1e-8)
