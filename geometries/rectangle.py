"""Structured rectangle (x0, x1) x (y0, y1) with n_x x n_y squares cut along one diagonal
('right': nested under refinement), boundary parts tagged by markers on the facet vertices.

Used by the unit-square and beam examples of Sections 2.2-3.3; meshes with n and 2n are nested.
"""
import math

import numpy as np

from damage_dolfinx import compat

from damage_dolfinx.geometries import Geometry, StructuredGrid


def rectangle(comm, p0, p1, nx: int, ny: int, boundary: dict) -> Geometry:
    """``boundary`` maps a facet tag to a marker x -> bool array (true on the part's vertices)."""
    msh = compat.create_rectangle(comm, p0, p1, (nx, ny))
    facets, values = [], []
    for tag, marker in boundary.items():
        found = compat.locate_entities_boundary(msh, 1, marker)
        facets.append(found)
        values.append(np.full(found.size, tag))
    tags = compat.meshtags(msh, 1, np.concatenate(facets), np.concatenate(values))
    Lx, Ly = p1[0] - p0[0], p1[1] - p0[1]
    return Geometry(msh, tags, h=math.hypot(Lx / nx, Ly / ny),
                    grid=StructuredGrid(p0[0], p0[1], Lx, Ly, nx, ny),
                    description=f"({p0[0]},{p1[0]})x({p0[1]},{p1[1]}), {nx}x{ny} grid, diagonals right")


def side(axis: int, value: float, lo=-np.inf, hi=np.inf, tol=1e-10):
    """Marker of the boundary segment {x_axis = value, lo <= x_other <= hi}."""
    other = 1 - axis

    def marker(x):
        return np.isclose(x[axis], value, atol=tol) & (x[other] >= lo - tol) & (x[other] <= hi + tol)
    return marker
