"""Box (0, side)^2 x (0, height) with a clamped box-shaped hole, structured tetrahedra.

The 3-D counterpart of ``square_with_hole`` (Section 2.1 Example 1): an n x n x n_z grid of
hexahedra, each cut into the 6 tetrahedra of DOLFINx's ``create_box``, without the hexahedra of
the hole (meshes with n and 2n are nested). The cells and vertices outside the hole are built
directly, each rank a slab of layers, and handed to ``create_mesh``: linear in the cells (cutting
the hole out of the full box with DOLFINx 0.5.2's ``create_submesh`` grew superlinearly;
benchmarks/README.md, "Why the defaults"). Gamma_D is the hole's boundary, Gamma_N the outer
boundary; optional Gamma_C faces (bilateral contact) by a marker.

* cavity ``hole_z = (2, 3)`` in a cube (side = height = 5): the 3-D example 2.1-ex1-3d;
* ``hole_z = None``: a hole through the whole height, i.e. the plate of thickness ``height``
  whose plane-stress limit is 2.1-ex1 (tests/test_3d.py).
"""
import math

import numpy as np

from damage_dolfinx import compat
from damage_dolfinx.core.parameters import InputError

from damage_dolfinx.geometries import GAMMA_C, GAMMA_D, GAMMA_N, Geometry


def _on_grid(value, cells_per_unit):
    return abs(value * cells_per_unit - round(value * cells_per_unit)) <= 1e-9


def box_with_hole(comm, n: int, side=5.0, height=5.0, nz=None, hole=(2.0, 3.0), hole_z=(2.0, 3.0),
                  contact=None) -> Geometry:
    """``n`` cells per side in x and y, ``nz`` (default n height/side) in z; ``contact`` is an
    optional marker x -> bool of boundary facets tagged Gamma_C instead of Gamma_N."""
    nz = max(1, int(round(n * height / side))) if nz is None else int(nz)
    lo, hi = hole
    if n < 1 or nz < 1 or not (_on_grid(lo, n / side) and _on_grid(hi, n / side)) or (
            hole_z is not None and not all(_on_grid(z, nz / height) for z in hole_z)):
        raise InputError(f"n = {n}, nz = {nz}: the hole faces must lie on grid planes of the "
                         f"{side} x {side} x {height} box (n a multiple of {side:g})")
    zlo, zhi = hole_z if hole_z is not None else (-np.inf, np.inf)
    tol = 1e-10 * max(side, height)
    msh = _box_minus_hole(comm, n, nz, side, height, hole, hole_z)

    def on_hole(x):
        return ((x[0] >= lo - tol) & (x[0] <= hi + tol) & (x[1] >= lo - tol) & (x[1] <= hi + tol)
                & (x[2] >= zlo - tol) & (x[2] <= zhi + tol))

    # the six faces of the box, one plane at a time (a facet whose vertices lie on two
    # different faces, e.g. a hole wall of a one-layer plate, is not on the outer boundary)
    outer = np.unique(np.concatenate([
        compat.locate_entities_boundary(msh, 2, lambda x, a=a, v=v: np.isclose(x[a], v))
        for a, v in ((0, 0.0), (0, side), (1, 0.0), (1, side), (2, 0.0), (2, height))]))
    hole_facets = compat.locate_entities_boundary(msh, 2, on_hole)
    parts = [(GAMMA_D, hole_facets[~np.isin(hole_facets, outer)])]
    if contact is not None:
        in_contact = np.isin(outer, compat.locate_entities_boundary(msh, 2, contact))
        parts += [(GAMMA_C, outer[in_contact])]
        outer = outer[~in_contact]
    parts += [(GAMMA_N, outer)]
    tags = compat.meshtags(msh, 2, np.concatenate([f for _, f in parts]),
                           np.concatenate([np.full(f.size, t) for t, f in parts]))
    kind = (f"cavity [{lo},{hi}]^2x[{hole_z[0]},{hole_z[1]}]" if hole_z is not None
            else f"through-hole [{lo},{hi}]^2")
    return Geometry(msh, tags, h=math.sqrt(2 * (side / n) ** 2 + (height / nz) ** 2),
                    description=f"(0,{side})^2x(0,{height}) minus {kind}, {n}x{n}x{nz} grid, "
                                "6 tetrahedra per hexahedron")


#: the 6 tetrahedra of a hexahedron in DOLFINx's create_box, corners numbered dx + 2 dy + 4 dz
_TETRAHEDRA = np.array([(0, 1, 3, 7), (0, 1, 7, 5), (0, 5, 7, 4), (0, 3, 2, 7), (0, 6, 4, 7),
                        (0, 2, 6, 7)])


def _box_minus_hole(comm, n, nz, side, height, hole, hole_z):
    """The mesh of the box minus the hole: vertex (ix, iy, iz) at (ix side/n, iy side/n,
    iz height/nz), numbered in create_box's order (x fastest) without the vertices strictly
    inside the hole; rank r builds the hexahedron layers iz in [r nz/p, (r+1) nz/p) and the
    r-th block of vertex rows."""
    m = n + 1
    ilo, ihi = (int(round(v * n / side)) for v in hole)
    klo, khi = ((int(round(v * nz / height)) for v in hole_z) if hole_z is not None
                else (-1, nz + 1))
    i, k = np.arange(m), np.arange(nz + 1)
    # vertices: all but those strictly inside the hole; number[full index] = compact index
    vx, vz = (i > ilo) & (i < ihi), (k > klo) & (k < khi)
    used = ~(vz[:, None, None] & vx[None, :, None] & vx[None, None, :]).ravel()
    number = np.cumsum(used, dtype=np.int64) - 1
    n_used = int(number[-1]) + 1
    r, p = comm.rank, comm.size
    # this rank's block of vertex rows
    full = np.flatnonzero(used)[n_used * r // p:n_used * (r + 1) // p]
    fz, rest = np.divmod(full, m * m)
    fy, fx = np.divmod(rest, m)
    x = np.column_stack([fx * (side / n), fy * (side / n), fz * (height / nz)])
    # this rank's hexahedra (outside the hole) and their 6 tetrahedra
    kz = np.arange(nz * r // p, nz * (r + 1) // p)
    hz, hy, hx = (a.ravel() for a in np.meshgrid(kz, np.arange(n), np.arange(n), indexing="ij"))
    hole_cell = (hx >= ilo) & (hx < ihi) & (hy >= ilo) & (hy < ihi) & (hz >= klo) & (hz < khi)
    hx, hy, hz = hx[~hole_cell], hy[~hole_cell], hz[~hole_cell]
    v0 = hx + m * (hy + m * hz)
    corner = np.array([dx + m * dy + m * m * dz for dz in (0, 1) for dy in (0, 1) for dx in (0, 1)])
    cells = number[(v0[:, None] + corner[None, :])[:, _TETRAHEDRA].reshape(-1, 4)]
    return compat.create_tet_mesh(comm, cells, x)


def block(comm, n: int, side=1.0, contact_faces=("x0", "y0", "y1", "z0", "z1")) -> Geometry:
    """The cube (0, side)^3 with n^3 x 6 tetrahedra, faces named x0, x1, y0, ... tagged Gamma_C
    (bilateral, u.nu = 0) when listed in ``contact_faces``, Gamma_N otherwise: with the default
    a traction on x1 puts the block in uniaxial strain."""
    msh = compat.create_box(comm, (0.0, 0.0, 0.0), (side, side, side), (n, n, n))
    facets, values = [], []
    for axis, name in enumerate("xyz"):
        for end, value in (("0", 0.0), ("1", side)):
            found = compat.locate_entities_boundary(
                msh, 2, lambda x, a=axis, v=value: np.isclose(x[a], v))
            facets.append(found)
            values.append(np.full(found.size, GAMMA_C if name + end in contact_faces else GAMMA_N))
    facets, values = np.concatenate(facets), np.concatenate(values)
    facets, first = np.unique(facets, return_index=True)  # an edge facet? (none: faces are planar)
    tags = compat.meshtags(msh, 2, facets, values[first])
    return Geometry(msh, tags, h=side * math.sqrt(3) / n,
                    description=f"cube (0,{side})^3, {n}^3 x 6 tetrahedra, bilateral on "
                                f"{', '.join(contact_faces)}")
