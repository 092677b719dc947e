"""Every demo (demos/demo_*.py) runs serially and under `mpirun -n 2`, as a user runs it, and
reaches its physics number: it exits with status 0 and prints, on rank 0 only, one line
``PHYSICS_CHECK <name> <value> <tolerance> PASS`` per check, with |value| <= tolerance."""
import re
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import ENV

DEMOS = sorted((Path(__file__).resolve().parent.parent / "demos").glob("demo_*.py"))
CHECK = re.compile(r"^PHYSICS_CHECK (\S+) (\S+) (\S+) (PASS|FAIL)$", re.M)


def run_demo(demo, np_, cwd):
    cmd = [sys.executable, str(demo)]
    if np_ > 1:
        cmd = ["mpirun", "-n", str(np_), *cmd]
    env = dict(ENV, DAMAGE_DOLFINX_DEMO_OUT=str(cwd))
    start = time.perf_counter()
    proc = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=600)
    return proc, time.perf_counter() - start


def test_there_are_demos():
    assert DEMOS


@pytest.mark.parametrize("np_", [1, pytest.param(2, marks=pytest.mark.mpi)],
                         ids=["serial", "np2"])
@pytest.mark.parametrize("demo", DEMOS, ids=[d.stem for d in DEMOS])
def test_demo(demo, np_, tmp_path):
    proc, seconds = run_demo(demo, np_, tmp_path)
    assert proc.returncode == 0, f"{demo.name} on {np_} rank(s) failed ({proc.returncode}):\n" \
                                 f"{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
    checks = CHECK.findall(proc.stdout)
    assert checks, f"{demo.name} printed no PHYSICS_CHECK line:\n{proc.stdout[-2000:]}"
    names = [c[0] for c in checks]
    assert len(names) == len(set(names)), f"a check printed twice (only rank 0 prints): {names}"
    for name, value, tolerance, verdict in checks:
        print(f"{demo.stem} np={np_} {seconds:.1f} s: {name} = {value} (tolerance {tolerance}) "
              f"{verdict}")
        assert verdict == "PASS" and abs(float(value)) <= float(tolerance), (name, value)
    assert seconds < 120, f"{demo.name} took {seconds:.0f} s (a demo takes under a minute)"
