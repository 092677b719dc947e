"""Structured box (x0, x1) x (y0, y1) x (z0, z1) with n_x x n_y x n_z hexahedra, each cut into 6
tetrahedra (DOLFINx ``create_box``), boundary parts tagged by markers on the facet vertices: the
3-D counterpart of ``rectangle`` for the 3-D contact examples (2.3, 3.1, 3.3 on a box,
normal compliance on a plane face). Meshes with n and 2n are nested.
"""
import math

import numpy as np

from damage_dolfinx import compat

from damage_dolfinx.geometries import Geometry


def box(comm, p0, p1, n, boundary: dict) -> Geometry:
    """``n`` = (nx, ny, nz); ``boundary`` maps a facet tag to a marker x -> bool array (true on
    the part's vertices); a facet two markers claim gets the first tag of ``boundary``."""
    msh = compat.create_box(comm, p0, p1, tuple(int(m) for m in n))
    facets, values = [], []
    for tag, marker in boundary.items():
        found = compat.locate_entities_boundary(msh, 2, marker)
        facets.append(found)
        values.append(np.full(found.size, tag))
    facets, values = np.concatenate(facets), np.concatenate(values)
    facets, first = np.unique(facets, return_index=True)  # first claim wins
    tags = compat.meshtags(msh, 2, facets, values[first])
    L = [b - a for a, b in zip(p0, p1)]
    return Geometry(msh, tags, h=math.sqrt(sum((Li / ni) ** 2 for Li, ni in zip(L, n))),
                    description=f"({p0[0]},{p1[0]})x({p0[1]},{p1[1]})x({p0[2]},{p1[2]}), "
                                f"{n[0]}x{n[1]}x{n[2]} grid, 6 tetrahedra per hexahedron")


def face(axis: int, value: float, tol=1e-10):
    """Marker of the plane face {x_axis = value} of a box."""
    def marker(x):
        return np.isclose(x[axis], value, atol=tol)
    return marker
