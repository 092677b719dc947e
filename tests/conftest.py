"""Shared helpers: run the CLI in a subprocess, serially or under `mpirun -n 2`."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

import reproduction.baselines  # noqa: F401 (registers the friction baselines in-process)

# oversubscription: OpenMPI 4 (Debian 12) reads OMPI_MCA_rmaps_base_oversubscribe, OpenMPI 5
# (Debian 13 and later, PRRTE) PRTE_MCA_rmaps_default_mapping_policy; a 3-rank test needs it on
# a 2-core runner. Transports: shared memory and TCP only (the Makefile says why: the probing
# of libfabric and UCX costs about 1 s per process start under Open MPI 6); a value set outside
# is kept.
for _name, _value in (("OMPI_MCA_btl", "^ofi,uct"), ("OMPI_MCA_pml", "ob1")):
    os.environ.setdefault(_name, _value)
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1",
           PRTE_MCA_rmaps_default_mapping_policy=":oversubscribe", OMP_NUM_THREADS="1",
           MPLBACKEND="Agg",
           # the reproduction's friction baselines (uzawa, penalty-duality), from the checkout
           DAMAGE_DOLFINX_PLUGINS="reproduction.baselines",
           PYTHONPATH=os.pathsep.join(filter(None, [
               os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
               os.environ.get("PYTHONPATH")])))


def tool_lines(stderr):
    """The lines of ``stderr`` that the package printed ("damage-dolfinx: ..."). Open MPI 5's
    launcher (PRRTE 3.0.8 in Debian 13) ends its own help messages (the MPI_ABORT notice) with a
    NUL byte, which then precedes whatever line a rank prints next: it is removed first."""
    return [line for line in stderr.replace("\0", "").splitlines()
            if line.startswith("damage-dolfinx:")]


def run_cli(args, np_=1, check=True, timeout=600):
    """Run `damage-dolfinx ARGS` (under mpirun -n np_ if np_ > 1); returns CompletedProcess."""
    cmd = [sys.executable, "-m", "damage_dolfinx.cli", *map(str, args)]
    if np_ > 1:
        cmd = ["mpirun", "-n", str(np_), *cmd]
    proc = subprocess.run(cmd, env=ENV, capture_output=True, text=True, timeout=timeout)
    if check and proc.returncode != 0:
        raise AssertionError(f"{' '.join(cmd)} failed ({proc.returncode}):\n{proc.stdout}\n{proc.stderr}")
    return proc


def load_run(out):
    """(summary dict, final fields npz) of a finished run folder."""
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    return summary, dict(np.load(os.path.join(out, "fields_final.npz")))


def rel_diff(a, b):
    return float(np.linalg.norm(np.asarray(a) - np.asarray(b)) / max(np.linalg.norm(b), 1e-300))


@pytest.fixture
def unit_square():
    from mpi4py import MPI
    from damage_dolfinx import compat
    return lambda n: compat.create_rectangle(MPI.COMM_WORLD, (0, 0), (1, 1), (n, n))


def serial_and_two_ranks(tmp_path, args, fields=("u", "zeta", "von_mises"), tol=1e-8):
    """Run ``args`` serially and on 2 ranks; assert the final fields agree to ``tol``
    (relative) and return ((serial summary, fields), (parallel summary, fields))."""
    run_cli(list(args) + ["--out", tmp_path / "s"])
    run_cli(list(args) + ["--out", tmp_path / "p"], np_=2)
    serial, parallel = load_run(tmp_path / "s"), load_run(tmp_path / "p")
    assert serial[0]["mpi_size"] == 1 and parallel[0]["mpi_size"] == 2
    for name in fields:
        assert np.allclose(serial[1][name + "_coords"], parallel[1][name + "_coords"], atol=1e-12)
        diff = rel_diff(parallel[1][name], serial[1][name])
        print(f"{name}: serial vs 2 ranks relative difference {diff:.2e}")
        assert diff < tol, name
    return serial, parallel


def owned_cell_keys(msh, keep=None):
    """Each owned cell (those of the mask ``keep`` if given) as the sorted tuple of its vertex
    coordinates (rounded to 1e-6), gathered from all ranks and sorted: the same cells give the
    same list whatever the numbering and partition."""
    from damage_dolfinx import compat
    conn = compat.geometry_dofmap(msh)[:compat.num_owned_cells(msh)]
    if keep is not None:
        conn = conn[keep]
    pts = np.round(msh.geometry.x[conn] * 1e6).astype(np.int64)
    keys = [tuple(sorted(map(tuple, t))) for t in pts]
    return sorted(sum(msh.comm.allgather(keys), []))


def python_on_two_ranks(code, timeout=300):
    """Run the Python ``code`` under mpirun -n 2 from the tests folder; assert it succeeds."""
    proc = subprocess.run(["mpirun", "-n", "2", sys.executable, "-c", code], env=ENV,
                          cwd=os.path.dirname(os.path.abspath(__file__)), capture_output=True,
                          text=True, timeout=timeout)
    assert proc.returncode == 0, proc.stdout + proc.stderr
