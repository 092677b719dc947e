"""The package as a user installs it (platforms/check-wheel.sh): the wheel built from the
checkout, installed into a fresh `python3 -m venv --system-site-packages` venv, and used from an
empty folder outside the checkout (command line, the README's own problem, a demo, a model from
a plugin file). Runs in every leg of `make test` (DOLFINx 0.5.2 on the host, 0.9 and 0.11 in
the roots); about 35 s."""
import shutil
import subprocess
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent


@pytest.mark.skipif(shutil.which("bash") is None, reason="needs bash")
def test_wheel_installs_and_runs_outside_the_checkout():
    start = time.perf_counter()
    proc = subprocess.run(["bash", str(REPO / "platforms" / "check-wheel.sh")],
                          capture_output=True, text=True, timeout=600)
    seconds = time.perf_counter() - start
    assert proc.returncode == 0, f"{proc.stdout[-4000:]}\n{proc.stderr[-4000:]}"
    out = proc.stdout
    assert "check-wheel: all passed" in out
    assert "all present; LICENSE, py.typed" in out
    assert "usage: damage-dolfinx" in out          # -h is the help
    assert "my-elastic: model 2.1 on a bar" in out  # the plugin module of the current folder
    assert seconds < 120, f"the wheel check took {seconds:.0f} s"
