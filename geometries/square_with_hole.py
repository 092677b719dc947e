"""Square (0, side)^2 with a centred square hole, structured (Section 2.1 Example 1).

The n x n grid of squares, each cut along its diagonal 'right' into the two triangles of
DOLFINx's ``create_rectangle``, without the squares of the hole; meshes with n and 2n are
therefore nested. The cells and vertices outside the hole are built directly, each rank a slab of
rows, and handed to ``create_mesh``: linear in the cells (cutting the hole out of the full grid
with DOLFINx 0.5.2's ``create_submesh`` grew faster than linearly; benchmarks/README.md, "Why the
defaults"). Gamma_D is
the hole boundary, Gamma_N the outer boundary.
"""
import math

import numpy as np

from damage_dolfinx import compat
from damage_dolfinx.core.parameters import InputError

from damage_dolfinx.geometries import GAMMA_D, GAMMA_N, Geometry, StructuredGrid


def square_with_hole(comm, n: int, side: float = 5.0, hole=(2.0, 3.0)) -> Geometry:
    lo, hi = hole
    cells_per_unit = n / side
    if n < 1 or abs(lo * cells_per_unit - round(lo * cells_per_unit)) > 1e-9 \
            or abs(hi * cells_per_unit - round(hi * cells_per_unit)) > 1e-9:
        raise InputError(f"n = {n}: the hole [{lo}, {hi}]^2 must lie on grid lines of the "
                         f"{side} x {side} square, i.e. n must be a positive multiple of "
                         f"{int(round(side / math.gcd(int(round(side)), 1)))}")
    tol = 1e-10 * side
    msh = _square_minus_hole(comm, n, side, hole)

    def on_hole(x):
        return (x[0] >= lo - tol) & (x[0] <= hi + tol) & (x[1] >= lo - tol) & (x[1] <= hi + tol)

    def on_outer(x):
        return (np.isclose(x[0], 0.0) | np.isclose(x[0], side)
                | np.isclose(x[1], 0.0) | np.isclose(x[1], side))

    hole_facets = compat.locate_entities_boundary(msh, 1, on_hole)
    outer_facets = compat.locate_entities_boundary(msh, 1, on_outer)
    tags = compat.meshtags(msh, 1, np.concatenate([hole_facets, outer_facets]),
                           np.concatenate([np.full(hole_facets.size, GAMMA_D),
                                           np.full(outer_facets.size, GAMMA_N)]))
    return Geometry(msh, tags, h=side * math.sqrt(2.0) / n,
                    grid=StructuredGrid(0.0, 0.0, side, side, n, n),
                    description=f"(0,{side})^2 minus [{lo},{hi}]^2, {n}x{n} grid, diagonals right")


#: the 2 triangles of a square in DOLFINx's create_rectangle (diagonal 'right'), corners
#: numbered dx + 2 dy
_TRIANGLES = np.array([(0, 1, 3), (0, 2, 3)])


def _square_minus_hole(comm, n, side, hole):
    """The mesh of the square minus the hole: vertex (ix, iy) at (ix side/n, iy side/n),
    numbered in create_rectangle's order (x fastest) without the vertices strictly inside the
    hole; rank r builds the rows of squares iy in [r n/p, (r+1) n/p) and the r-th block of
    vertex rows."""
    m = n + 1
    ilo, ihi = (int(round(v * n / side)) for v in hole)
    i = np.arange(m)
    # vertices: all but those strictly inside the hole; number[full index] = compact index
    inner = (i > ilo) & (i < ihi)
    used = ~(inner[:, None] & inner[None, :]).ravel()
    number = np.cumsum(used, dtype=np.int64) - 1
    n_used = int(number[-1]) + 1
    r, p = comm.rank, comm.size
    full = np.flatnonzero(used)[n_used * r // p:n_used * (r + 1) // p]
    fy, fx = np.divmod(full, m)
    x = np.column_stack([fx * (side / n), fy * (side / n)])
    # this rank's squares (outside the hole) and their 2 triangles
    hy, hx = (a.ravel() for a in np.meshgrid(np.arange(n * r // p, n * (r + 1) // p),
                                             np.arange(n), indexing="ij"))
    hole_cell = (hx >= ilo) & (hx < ihi) & (hy >= ilo) & (hy < ihi)
    hx, hy = hx[~hole_cell], hy[~hole_cell]
    v0 = hx + m * hy
    corner = np.array([dx + m * dy for dy in (0, 1) for dx in (0, 1)])
    cells = number[(v0[:, None] + corner[None, :])[:, _TRIANGLES].reshape(-1, 3)]
    return compat.create_simplex_mesh(comm, cells, x)
