"""A model of your own, written in a script (demos/demo_own_model.py: model 2.2 with normal
compliance instead of Tresca friction): serial = 2 ranks, a run started on 2 ranks and restarted
on 1 equals the uninterrupted serial run, and the declared history columns are a contract."""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import ENV

DEMO = Path(__file__).resolve().parent.parent / "demos" / "demo_own_model.py"


def script(np_, out, code):
    """Run the demo (it defines the model and the problem), then ``code``, on np_ ranks."""
    text = (f"import runpy; import damage_dolfinx as dd; "
            f"ns = runpy.run_path({str(DEMO)!r}); problem = ns['problem']; {code}")
    cmd = [sys.executable, "-c", text]
    if np_ > 1:
        cmd = ["mpirun", "-n", str(np_), *cmd]
    proc = subprocess.run(cmd, env=dict(ENV, DAMAGE_DOLFINX_DEMO_OUT=str(out)), cwd=out,
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-3000:]
    return proc.stdout


def fields(folder):
    data = np.load(folder / "fields_final.npz")
    return {k: data[k] for k in data.files}


def same(a, b, rtol):
    for name in a:
        if name.endswith("_coords"):
            assert np.allclose(a[name], b[name], atol=1e-12), name
            continue
        scale = max(np.abs(a[name]).max(), 1e-300)
        assert np.abs(a[name] - b[name]).max() <= rtol * scale, \
            (name, np.abs(a[name] - b[name]).max() / scale)


@pytest.mark.mpi
def test_own_model_serial_equals_two_ranks_and_restarts_on_another_rank_count(tmp_path):
    serial, parallel = tmp_path / "serial", tmp_path / "parallel"
    serial.mkdir()
    parallel.mkdir()
    # 2 ranks: the demo, then a run to t = 0.25 only
    script(2, parallel, "dd.run(problem, 'half', T=0.25, progress=False, figures=False, "
                        "overwrite=True)")
    # 1 rank: the demo, then the 2-rank run restarted to T = 0.5 on 1 rank
    out = script(1, serial, "s = dd.run(problem, str(ns['out'].parent.parent / 'parallel' / "
                            "'half'), T=0.5, restart=True, progress=False, figures=False); "
                            "print('RESTARTS', s['restarts'])")
    assert "'previous_mpi_size': 2" in out and "'mpi_size': 1" in out
    reference = fields(serial / "own_model" / "run")            # serial, uninterrupted to T
    same(reference, fields(parallel / "own_model" / "run"), 1e-10)    # serial = 2 ranks
    same(reference, fields(parallel / "half"), 1e-10)           # 2 ranks -> restart on 1


def test_a_scalar_without_a_column_is_an_error(tmp_path):
    out = tmp_path / "x"
    out.mkdir()
    code = ("import pytest; from damage_dolfinx.runtime.runner import ColumnError; "
            "cls = ns['CompliantKelvinVoigt']; "
            "Bad = type('Bad', (cls,), {'id': 'bad', 'history_columns': (), "
            "'__module__': 'x'}); "
            "problem.model = Bad; "
            "exc = pytest.raises(ColumnError, dd.run, problem, 'bad', progress=False, "
            "figures=False); print('RAISED', exc.value)")
    stdout = script(1, out, code)
    assert "RAISED" in stdout and "contact_force" in stdout
