"""geometries/box_with_hole.py builds the box minus the hole directly (scaling): the
same tetrahedra as DOLFINx's create_box without the cells inside the hole, the expected facet
tags, serially and on 2 ranks. Small meshes: about a second."""
import numpy as np
import pytest
from mpi4py import MPI

from conftest import owned_cell_keys, python_on_two_ranks
from damage_dolfinx import compat
from damage_dolfinx.geometries import GAMMA_D, GAMMA_N
from damage_dolfinx.geometries.box_with_hole import box_with_hole


def box_cells_outside(comm, n, side, height, nz, hole, hole_z):
    """The reference: create_box's cells whose midpoint is outside the hole."""
    full = compat.create_box(comm, (0, 0, 0), (side, side, height), (n, n, nz))
    mid = compat.cell_midpoints(full)[:compat.num_owned_cells(full)]
    zlo, zhi = hole_z if hole_z is not None else (-np.inf, np.inf)
    inside = ((mid[:, 0] > hole[0]) & (mid[:, 0] < hole[1]) & (mid[:, 1] > hole[0])
              & (mid[:, 1] < hole[1]) & (mid[:, 2] > zlo) & (mid[:, 2] < zhi))
    return owned_cell_keys(full, ~inside)


CASES = {"cavity n=5": dict(n=5), "cavity n=10": dict(n=10),
         "plate": dict(n=10, height=1.0, nz=1, hole_z=None),
         "cavity, nz != n": dict(n=10, height=2.5, nz=5, hole_z=(1.0, 2.0))}


@pytest.mark.parametrize("case", list(CASES))
def test_same_cells_as_create_box_minus_hole(case):
    comm = MPI.COMM_WORLD
    args = CASES[case]
    g = box_with_hole(comm, **args)
    n, height = args["n"], args.get("height", 5.0)
    nz = args.get("nz", n)
    want = box_cells_outside(comm, n, 5.0, height, nz, (2.0, 3.0), args.get("hole_z", (2.0, 3.0)))
    got = owned_cell_keys(g.mesh)
    assert len(got) == len(set(got)) == len(want) and got == want
    # every vertex is used by a cell (none inside the hole left over)
    n_vertices = g.mesh.topology.index_map(0).size_global
    assert n_vertices == len({v for cell in got for v in cell})
    # facet tags: Gamma_D the hole walls, Gamma_N the six outer faces (2 triangles per square)
    tags = g.facet_tags
    owned = tags.indices < g.mesh.topology.index_map(2).size_local
    count = {t: comm.allreduce(int(np.sum(tags.values[owned] == t))) for t in (GAMMA_D, GAMMA_N)}
    m = n // 5  # grid cells per unit length in x, y
    mz = nz / height
    if args.get("hole_z", (2.0, 3.0)) is None:
        assert count[GAMMA_D] == 4 * 2 * m * nz
        holes_on_faces = 2 * 2 * m * m  # the hole opens through top and bottom
    else:
        zlo, zhi = args.get("hole_z", (2.0, 3.0))
        assert count[GAMMA_D] == 2 * (2 * m * m + 4 * m * round((zhi - zlo) * mz))
        holes_on_faces = 0
    assert count[GAMMA_N] == 2 * (2 * n * n + 4 * n * nz) - holes_on_faces


@pytest.mark.mpi
def test_same_cells_on_two_ranks():
    """Each rank builds a slab of layers; the partitioned mesh has the same cells."""
    python_on_two_ranks("from test_box_with_hole import *\n"
                        "for case in CASES: test_same_cells_as_create_box_minus_hole(case)\n")
