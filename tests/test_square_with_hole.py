"""geometries/square_with_hole.py builds the square minus the hole directly (2.1-ex1, linear
in the cells): the same triangles as DOLFINx's create_rectangle (diagonals 'right') without the
cells inside the hole, every vertex used, the expected facet tags, serially and on 2 ranks.
Small meshes: about a second."""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

from damage_dolfinx import compat
from damage_dolfinx.geometries import GAMMA_D, GAMMA_N
from damage_dolfinx.geometries.square_with_hole import square_with_hole


def _keys(msh, conn):
    pts = np.round(msh.geometry.x[conn][:, :, :2] * 1e6).astype(np.int64)
    keys = [tuple(sorted(map(tuple, t))) for t in pts]
    return sorted(sum(msh.comm.allgather(keys), []))


def _owned_conn(msh):
    dm = msh.geometry.dofmap
    conn = dm.array.reshape(-1, 3) if hasattr(dm, "array") else np.asarray(dm)
    return conn[:compat.num_owned_cells(msh)]


@pytest.mark.parametrize("n", [5, 10, 20])
def test_same_cells_as_create_rectangle_minus_hole(n):
    comm = MPI.COMM_WORLD
    g = square_with_hole(comm, n)
    full = compat.create_rectangle(comm, (0.0, 0.0), (5.0, 5.0), (n, n))
    mid = compat.cell_midpoints(full)[:compat.num_owned_cells(full)]
    inside = (mid[:, 0] > 2.0) & (mid[:, 0] < 3.0) & (mid[:, 1] > 2.0) & (mid[:, 1] < 3.0)
    want = _keys(full, _owned_conn(full)[~inside])
    got = _keys(g.mesh, _owned_conn(g.mesh))
    assert len(got) == len(set(got)) == len(want) == 2 * (n * n - (n // 5) ** 2) and got == want
    assert g.mesh.topology.index_map(0).size_global == len({v for c in got for v in c})
    tags = g.facet_tags
    owned = tags.indices < g.mesh.topology.index_map(1).size_local
    count = {t: comm.allreduce(int(np.sum(tags.values[owned] == t))) for t in (GAMMA_D, GAMMA_N)}
    assert count == {GAMMA_D: 4 * (n // 5), GAMMA_N: 4 * n}


@pytest.mark.mpi
def test_same_cells_on_two_ranks():
    """Each rank builds a slab of rows; the partitioned mesh has the same cells."""
    from conftest import ENV
    code = ("from test_square_with_hole import *\n"
            "for n in (5, 10, 20): test_same_cells_as_create_rectangle_minus_hole(n)\n")
    proc = subprocess.run(["mpirun", "-n", "2", sys.executable, "-c", code], env=ENV,
                          cwd=str(Path(__file__).parent), capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
