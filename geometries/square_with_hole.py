"""Square (0, side)^2 with a centred square hole, structured (Section 2.1 Example 1).

The n x n grid with diagonals 'right' is built by DOLFINx and the cells inside the hole are
removed with ``create_submesh``; meshes with n and 2n are therefore nested. Gamma_D is the hole
boundary, Gamma_N the outer boundary.
"""
import math

import numpy as np

from damage_dolfinx import compat
from damage_dolfinx.parameters import InputError

from damage_dolfinx.geometries import GAMMA_D, GAMMA_N, Geometry, StructuredGrid


def square_with_hole(comm, n: int, side: float = 5.0, hole=(2.0, 3.0)) -> Geometry:
    lo, hi = hole
    cells_per_unit = n / side
    if n < 1 or abs(lo * cells_per_unit - round(lo * cells_per_unit)) > 1e-9 \
            or abs(hi * cells_per_unit - round(hi * cells_per_unit)) > 1e-9:
        raise InputError(f"n = {n}: the hole [{lo}, {hi}]^2 must lie on grid lines of the "
                         f"{side} x {side} square, i.e. n must be a positive multiple of "
                         f"{int(round(side / math.gcd(int(round(side)), 1)))}")
    full = compat.create_rectangle(comm, (0.0, 0.0), (side, side), (n, n))
    tol = 1e-10 * side

    mid = compat.cell_midpoints(full)
    outside = (mid[:, 0] < lo) | (mid[:, 0] > hi) | (mid[:, 1] < lo) | (mid[:, 1] > hi)
    keep = np.flatnonzero(outside[:compat.num_owned_cells(full)]).astype(np.int32)
    msh = compat.create_submesh(full, 2, keep)

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
