"""Coarse-to-fine transfer on meshes that are not nested (a gmsh family): point evaluation.

A coarse field u_H (P1 or DG0, any block size) is compared with the reference u_h on the
reference (finest) mesh through its values at the reference's degrees of freedom,

    (I_h u_H)(x_i) = u_H(x_i),   x_i the reference's nodes (P1) or cell midpoints (DG0),

evaluated exactly in the coarse cell that contains x_i (bounding-box tree and collision test,
``compat.locate_points``; ``Function.eval``). Where the two meshes approximate a curved boundary
differently, a reference point can lie just outside the coarse mesh: it takes the value of the
nearest coarse cell's polynomial (extrapolated), and the largest such distance is kept
(``outside``): a family whose meshes do not cover the same domain, up to a fraction of the coarse
cell size, is refused before any step (convergence.py). The error is then the norm of
u_h - I_h u_H on the reference mesh, as for nested meshes (where I_h u_H = u_H exactly).

The two halves have the interface of ``post.NestedTransfer``: :class:`PointValues` (coarse side,
on the ranks of the coarse mesh) gives ``grid_values(u_H)``, the values at all reference points
in one global order, and :class:`ReferencePoints` (fine side, on the reference's ranks) has that
order (``points``, every rank) and ``to_fine(values, u)``.
"""
from __future__ import annotations

import numpy as np
from mpi4py import MPI

from damage_dolfinx import compat

#: a family is refused when reference points lie farther than this fraction of the coarse
#: mesh size h outside the coarse mesh (their meshes do not cover the same domain)
OUTSIDE_TOLERANCE = 0.5

COMPARISON = ("the coarse fields evaluated exactly at the reference mesh's nodes (P1) and cell "
              "midpoints (DG0) by point location in the coarse mesh (meshes not nested), the "
              "error integrated on the reference mesh")
NESTED_COMPARISON = ("the coarse fields transferred exactly to the nested reference mesh, the "
                     "error integrated on the reference mesh")


class ReferencePoints:
    """The reference space's dof points in a global order (rank by rank), known on every rank
    of the reference mesh; ``to_fine`` puts values in that order into a reference Function."""

    def __init__(self, V):
        self.V, comm = V, V.mesh.comm
        owned = V.dofmap.index_map.size_local
        self.bs = V.dofmap.index_map_bs
        gdim = V.mesh.geometry.dim
        mine = V.tabulate_dof_coordinates()[:owned, :gdim]
        parts = comm.allgather(mine)
        self.offset = sum(len(p) for p in parts[:comm.rank])
        self.owned = owned
        self.points = np.concatenate(parts)
        self.grid_shape = (len(self.points), self.bs)

    def to_fine(self, values, u):
        part = np.asarray(values).reshape(-1, self.bs)[self.offset:self.offset + self.owned]
        u.x.array[:self.owned * self.bs] = part.ravel()
        u.x.scatter_forward()


class PointValues:
    """The values of a coarse Function of space ``V`` at ``points`` (N, gdim), on every rank of
    the coarse mesh (collective there). ``outside``: the largest distance from a point not in
    the coarse mesh to the nearest coarse cell midpoint (0 when every point is inside)."""

    def __init__(self, V, points):
        from scipy.spatial import cKDTree
        msh, comm = V.mesh, V.mesh.comm
        self.comm, self.bs = comm, V.dofmap.index_map_bs
        self.grid_shape = (len(points), self.bs)
        gdim = msh.geometry.dim
        xyz = np.zeros((len(points), 3))
        xyz[:, :gdim] = points
        owned = compat.num_owned_cells(msh)
        cells = compat.locate_points(msh, xyz)
        cells[cells >= owned] = -1  # owned cells only: each point once
        found = (comm.allreduce((cells >= 0).astype(np.int32), op=MPI.SUM) > 0)
        distance = np.full(len(points), np.inf)
        lost = np.flatnonzero(~found)
        if lost.size and owned:
            mids = compat.cell_midpoints(msh)[:owned, :gdim]
            distance[lost], nearest = cKDTree(mids).query(points[lost])
            cells[lost] = nearest
        best = comm.allreduce(distance, op=MPI.MIN)
        # the rank evaluating each point: the lowest with the cell (or the nearest cell)
        claim = np.where((cells >= 0) & (found | (distance <= best)), comm.rank, comm.size)
        self.mine = np.flatnonzero(comm.allreduce(claim, op=MPI.MIN) == comm.rank)
        self.cells, self.xyz = cells[self.mine], xyz[self.mine]
        self.outside = float(best[lost].max()) if lost.size else 0.0

    def grid_values(self, u):
        local = np.zeros(self.grid_shape)
        if self.mine.size:
            local[self.mine] = np.asarray(u.eval(self.xyz, self.cells)).reshape(
                self.mine.size, self.bs)
        return self.comm.allreduce(local, op=MPI.SUM) if self.comm.size > 1 else local
