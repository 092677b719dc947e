"""Ring (box-end) wrench on a hexagonal screw (Section 3.3 Example 3, thesis Figure 3.19), gmsh.

Our default (docs/models.md, section 3.3), built in a local frame and then rotated: head = disc of
radius ``head_radius`` (1.2) at the origin with a regular hexagonal hole of across-flats
``across_flats`` (1.0; the screw occupies the hole); handle = rectangle x in [``handle_start``,
``handle_end``] = [1, 10], |y| <= ``handle_width``/2 = 0.4; loaded part = handle top face for x in
[``load_start``, ``handle_end``] = [9, 10]; the body is rotated by ``rotation_deg`` (-45 degrees)
about the origin, so that the loaded face's outward normal is (1, 1)/sqrt(2) and the traction
(-1e5, -1e5) is a pure pressure. The hexagon has one flat facing the handle (flat normals at
``hex_angle_deg`` + 60 j degrees in the local frame, default 0).

Facet tags: GAMMA_C = the six hexagon faces (contact with the rigid screw behind them; the
body's outward normal there points into the hole, so u.nu > 0 is interpenetration), GAMMA_N =
the loaded face, FREE = every other exterior face (traction free). Gamma_D is empty.
Element size ``h`` (0.15), ``h_contact`` (0.05) on the hexagon, growing to h over a distance
``transition`` (0.5). The model is meshed on rank 0 and distributed.
"""
from __future__ import annotations

import math

from damage_dolfinx.geometries import lazy_gmsh as gmsh

from damage_dolfinx import compat
from damage_dolfinx.core.parameters import InputError

from damage_dolfinx.geometries import GAMMA_C, GAMMA_N, Geometry, gmsh_session

#: traction-free exterior faces
FREE = 4


def hexagon_vertices(across_flats: float, hex_angle_deg: float = 0.0):
    """Vertices of the regular hexagon with the given across-flats distance whose flat normals
    point at hex_angle_deg + 60 j degrees (vertices half-way between, at the circumradius)."""
    R = across_flats / math.sqrt(3.0)  # circumradius = apothem / cos(30 deg)
    a0 = math.radians(hex_angle_deg + 30.0)
    return [(R * math.cos(a0 + j * math.pi / 3), R * math.sin(a0 + j * math.pi / 3))
            for j in range(6)]


def _check(head_radius, across_flats, handle_start, handle_end, handle_width, load_start):
    if not (across_flats / math.sqrt(3.0) < head_radius):
        raise InputError("the hexagonal hole must lie inside the head disc")
    if not (across_flats / math.sqrt(3.0) < handle_start
            and math.hypot(handle_start, handle_width / 2) < head_radius):
        raise InputError("the handle must start inside the head disc, outside the hole")
    if not (handle_start < load_start < handle_end):
        raise InputError("the loaded face must be a part of the handle's top face")


def wrench(comm, h: float = 0.15, h_contact: float = 0.05, head_radius: float = 1.2,
           across_flats: float = 1.0, handle_start: float = 1.0, handle_end: float = 10.0,
           handle_width: float = 0.8, load_start: float = 9.0, rotation_deg: float = -45.0,
           hex_angle_deg: float = 0.0, transition: float = 0.5) -> Geometry:
    """The wrench as a :class:`Geometry` (facet tags GAMMA_C, GAMMA_N, FREE)."""
    _check(head_radius, across_flats, handle_start, handle_end, handle_width, load_start)
    if not (h > 0 and h_contact > 0):
        raise InputError(f"mesh sizes must be positive, got h = {h}, h_contact = {h_contact}")
    error = None
    if comm.rank == 0:
        try:
            _model(h, h_contact, head_radius, across_flats, handle_start, handle_end, handle_width,
                   load_start, rotation_deg, hex_angle_deg, transition)
        except Exception as exc:  # reported on every rank, not only where gmsh runs
            error = f"wrench geometry: {exc}"
            gmsh.model.remove()
    msh, facet_tags = _to_mesh(comm, error, gdim=2)
    return Geometry(msh, facet_tags, h=h,
                    description=f"ring wrench (G35): head R={head_radius}, hexagon across flats "
                                f"{across_flats}, handle [{handle_start},{handle_end}]x"
                                f"[-{handle_width / 2},{handle_width / 2}], load on x in "
                                f"[{load_start},{handle_end}], rotated {rotation_deg} deg; gmsh "
                                f"h={h}, h_contact={h_contact}")


def _model(h, h_contact, head_radius, across_flats, handle_start, handle_end, handle_width,
           load_start, rotation_deg, hex_angle_deg, transition):
    """The tagged and meshed gmsh model (rank 0)."""
    gmsh_session()
    gmsh.model.add("wrench")
    surfaces = _build(head_radius, across_flats, handle_start, handle_end, handle_width,
                      load_start, hex_angle_deg, rotation_deg)
    boundary = [t for _, t in gmsh.model.getBoundary(surfaces, combined=True, oriented=False)]
    hexagon, loaded = _classify(boundary, across_flats, handle_width, load_start, handle_end,
                                rotation_deg)
    free = sorted(set(boundary) - set(hexagon) - set(loaded))
    gmsh.model.addPhysicalGroup(2, [t for _, t in surfaces], 1)
    gmsh.model.addPhysicalGroup(1, hexagon, GAMMA_C)
    gmsh.model.addPhysicalGroup(1, loaded, GAMMA_N)
    gmsh.model.addPhysicalGroup(1, free, FREE)
    _mesh_sizes(hexagon, h, h_contact, transition)
    gmsh.model.mesh.generate(2)


def _build(head_radius, across_flats, handle_start, handle_end, handle_width, load_start,
           hex_angle_deg, rotation_deg):
    """OCC model: built in the local frame, fused, cut and rotated; returns the surfaces."""
    occ = gmsh.model.occ
    w2 = handle_width / 2
    disc = occ.addDisk(0, 0, 0, head_radius, head_radius)
    # the handle's top face is split at x = load_start so that the loaded part is one curve
    corners = [(handle_start, -w2), (handle_end, -w2), (handle_end, w2), (load_start, w2),
               (handle_start, w2)]
    pts = [occ.addPoint(x, y, 0) for x, y in corners]
    lines = [occ.addLine(pts[i], pts[(i + 1) % len(pts)]) for i in range(len(pts))]
    handle = occ.addPlaneSurface([occ.addCurveLoop(lines)])
    hpts = [occ.addPoint(x, y, 0) for x, y in hexagon_vertices(across_flats, hex_angle_deg)]
    hlines = [occ.addLine(hpts[i], hpts[(i + 1) % 6]) for i in range(6)]
    hole = occ.addPlaneSurface([occ.addCurveLoop(hlines)])
    unify = gmsh.option.getNumber("Geometry.OCCUnionUnify")
    gmsh.option.setNumber("Geometry.OCCUnionUnify", 0)  # keep the split of the top face
    try:
        body, _ = occ.fuse([(2, disc)], [(2, handle)])
        body, _ = occ.cut(body, [(2, hole)])
    finally:
        gmsh.option.setNumber("Geometry.OCCUnionUnify", unify)
    surfaces = [(2, t) for d, t in body if d == 2]
    occ.rotate(surfaces, 0, 0, 0, 0, 0, 1, math.radians(rotation_deg))
    occ.synchronize()
    return [(2, t) for _, t in gmsh.model.getEntities(2)]  # OCC may renumber on rotation


def _to_mesh(comm, error, gdim):
    """The gmsh model built on rank 0 as a distributed mesh, or its error as one InputError line
    on every rank (the wrench and the wrench plate)."""
    error = comm.bcast(error, root=0)
    if error is not None:
        raise InputError(error)
    msh, _, facet_tags = compat.model_to_mesh(gmsh.model, comm, 0, gdim=gdim)
    if comm.rank == 0:
        gmsh.model.remove()
    return msh, facet_tags


def _classify(entities, across_flats, handle_width, load_start, handle_end, rotation_deg,
              dim=1):
    """(hexagon, loaded): the boundary curves (dim 1) or side faces (dim 2, the extruded plate)
    whose parametric midpoint, mapped back to the local frame, lies on a hexagon flat or on the
    loaded end of the handle. A curved face's midpoint is on the face; its centre of mass is not."""
    c, s = math.cos(math.radians(rotation_deg)), math.sin(math.radians(rotation_deg))
    w2, tol = handle_width / 2, 1e-6 * handle_end
    hexagon, loaded = [], []
    for tag in entities:
        lo, hi = gmsh.model.getParametrizationBounds(dim, tag)
        mid = [0.5 * (a + b) for a, b in zip(lo, hi)]
        X, Y, _ = gmsh.model.getValue(dim, tag, mid)
        x, y = c * X + s * Y, -s * X + c * Y  # inverse rotation
        if math.hypot(x, y) <= across_flats / 2 + tol:  # flat midpoints lie at the apothem
            hexagon.append(tag)
        elif abs(y - w2) <= tol and load_start - tol <= x <= handle_end + tol:
            loaded.append(tag)
    if len(hexagon) != 6 or len(loaded) != 1:
        raise RuntimeError(f"wrench: found {len(hexagon)} hexagon faces and {len(loaded)} "
                           "loaded faces (expected 6 and 1)")
    return hexagon, loaded


def _mesh_sizes(hexagon, h, h_contact, transition, dim=1):
    """Size h_contact on the hexagon (its curves, dim 1, or faces, dim 2), growing linearly to h
    at distance ``transition``."""
    field = gmsh.model.mesh.field
    dist = field.add("Distance")
    # option names of gmsh >= 4.9, then of gmsh 4.8; samples per curve / per face direction
    names = {1: (("CurvesList", "Sampling"), ("EdgesList", "NNodesByEdge")),
             2: (("SurfacesList", "Sampling"), ("FacesList", "NNodesByEdge"))}[dim]
    for entities, sampling in names:
        try:
            field.setNumbers(dist, entities, hexagon)
            field.setNumber(dist, sampling, {1: 100, 2: 30}[dim])
            break
        except Exception:
            continue
    thr = field.add("Threshold")
    field.setNumber(thr, "InField", dist)
    field.setNumber(thr, "SizeMin", min(h_contact, h))
    field.setNumber(thr, "SizeMax", h)
    field.setNumber(thr, "DistMin", 0.0)
    field.setNumber(thr, "DistMax", transition)
    field.setAsBackgroundMesh(thr)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
