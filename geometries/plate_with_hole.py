"""A rectangular plate (0, L) x (0, H) with a circular hole of radius r at its centre, meshed by
gmsh with element size h (unstructured, not nested from one h to the next).

Physical names (facet groups, usable in ``Problem(boundaries=...)``): ``left`` (x = 0, tag 1),
``right`` (x = L, tag 2), ``bottom`` (tag 3), ``top`` (tag 4), ``hole`` (tag 5); the cells are
the physical surface ``plate``. ``plate_with_hole_family(h0)`` is the mesh family
``(comm, n) -> Geometry`` with h = h0 / n.
"""
from damage_dolfinx.geometries import Geometry, generate_2d, gmsh_session

#: tag of each physical name
TAGS = {"left": 1, "right": 2, "bottom": 3, "top": 4, "hole": 5}


def plate_with_hole_model(h: float, L: float = 2.0, H: float = 1.0, r: float = 0.25):
    """The meshed gmsh model (current ``gmsh.model``; call on one rank)."""
    gmsh = gmsh_session()
    gmsh.model.add("plate_with_hole")
    occ = gmsh.model.occ
    plate = occ.addRectangle(0, 0, 0, L, H)
    hole = occ.addDisk(L / 2, H / 2, 0, r, r)
    body, _ = occ.cut([(2, plate)], [(2, hole)])
    occ.synchronize()
    groups = {name: [] for name in TAGS}
    eps = 1e-3 * min(L, H)  # OCC bounding boxes carry a tolerance
    for dim, tag in gmsh.model.getBoundary(body, oriented=False):
        x0, y0, _, x1, y1, _ = gmsh.model.getBoundingBox(dim, tag)
        if x1 - x0 < eps:
            groups["left" if x0 < eps else "right"].append(tag)
        elif y1 - y0 < eps:
            groups["bottom" if y0 < eps else "top"].append(tag)
        else:
            groups["hole"].append(tag)
    gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, [body[0][1]], 1), "plate")
    for name, tags in groups.items():
        gmsh.model.setPhysicalName(1, gmsh.model.addPhysicalGroup(1, tags, TAGS[name]), name)
    generate_2d(h)
    return gmsh.model


def plate_with_hole(comm, h: float, L: float = 2.0, H: float = 1.0, r: float = 0.25) -> Geometry:
    """The plate as a Geometry (meshed on rank 0, distributed), with its physical names."""
    from damage_dolfinx.problem.meshes import from_gmsh
    gmsh = gmsh_session()
    if comm.rank == 0:
        plate_with_hole_model(h, L, H, r)
    try:
        geometry = from_gmsh(comm=comm, dim=2)
    finally:
        if comm.rank == 0:
            gmsh.model.remove()
    geometry.h = h
    geometry.description = f"plate {L} x {H} with a hole of radius {r}, gmsh h = {h}"
    return geometry


def plate_with_hole_family(h0: float = 0.2, **dims):
    """The mesh family (comm, n) -> plate_with_hole(comm, h0 / n)."""
    return lambda comm, n: plate_with_hole(comm, h0 / n, **dims)
