"""The ring wrench of Section 3.3 Example 3 (thesis Figure 3.19) as a plate with thickness: the
2-D outline of ``wrench.py`` (head disc R = 1.2 with a hexagonal hole across flats 1.0,
handle [1, 10] x [-0.4, 0.4], rotated by -45 degrees) extruded along z by ``thickness``.

Thickness 0.4 by default: half the handle width, about the proportion of a real box-end wrench
(a 13 mm wrench, the unit here being the across-flats size of the screw, is about 5-6 mm thick
with a 10-11 mm wide handle). The plate spans 0 <= z <= thickness.

Facet tags, the extrusions of the 2-D parts: GAMMA_C = the six hexagon faces (the sides of the
hole, in contact with the rigid screw; outward normal pointing into the hole), GAMMA_N = the
loaded face (the extruded top of the handle for x in [9, 10] in the local frame, outward normal
(1, 1, 0)/sqrt(2)), FREE = everything else (the outer sides and the two plate faces z = 0 and
z = thickness), traction-free. Gamma_D is empty. Element size ``h`` (0.2),
``h_contact`` (0.1) on the hexagon faces, growing to h over ``transition`` (0.5). Meshed on
rank 0 (gmsh, tetrahedra) and distributed.
"""
from __future__ import annotations

from damage_dolfinx.geometries import lazy_gmsh as gmsh

from damage_dolfinx.core.parameters import InputError

from damage_dolfinx.geometries import GAMMA_C, GAMMA_N, Geometry, gmsh_session
from damage_dolfinx.geometries.wrench import FREE, _build, _check, _classify, _mesh_sizes, _to_mesh

__all__ = ["wrench_plate", "FREE"]


def wrench_plate(comm, h: float = 0.2, h_contact: float = 0.1, thickness: float = 0.4,
                 head_radius: float = 1.2, across_flats: float = 1.0, handle_start: float = 1.0,
                 handle_end: float = 10.0, handle_width: float = 0.8, load_start: float = 9.0,
                 rotation_deg: float = -45.0, hex_angle_deg: float = 0.0,
                 transition: float = 0.5) -> Geometry:
    """The wrench extruded to a plate, as a :class:`Geometry` (facet tags GAMMA_C, GAMMA_N,
    FREE)."""
    _check(head_radius, across_flats, handle_start, handle_end, handle_width, load_start)
    if not (h > 0 and h_contact > 0 and thickness > 0):
        raise InputError(f"mesh sizes and thickness must be positive, got h = {h}, "
                         f"h_contact = {h_contact}, thickness = {thickness}")
    error = None
    if comm.rank == 0:
        try:
            gmsh_session()
            gmsh.model.add("wrench_plate")
            surfaces = _build(head_radius, across_flats, handle_start, handle_end, handle_width,
                              load_start, hex_angle_deg, rotation_deg)
            gmsh.model.occ.extrude(surfaces, 0, 0, thickness)
            gmsh.model.occ.synchronize()
            volumes = gmsh.model.getEntities(3)
            faces = [t for _, t in gmsh.model.getBoundary(volumes, combined=True, oriented=False)]
            tol = 1e-6 * handle_end
            sides = [t for t in faces  # not the plate faces z = 0 and z = thickness
                     if abs(gmsh.model.occ.getCenterOfMass(2, t)[2] - thickness / 2) <= tol]
            hexagon, loaded = _classify(sides, across_flats, handle_width, load_start,
                                        handle_end, rotation_deg, dim=2)
            gmsh.model.addPhysicalGroup(3, [t for _, t in volumes], 1)
            gmsh.model.addPhysicalGroup(2, hexagon, GAMMA_C)
            gmsh.model.addPhysicalGroup(2, loaded, GAMMA_N)
            gmsh.model.addPhysicalGroup(2, sorted(set(faces) - set(hexagon) - set(loaded)), FREE)
            _mesh_sizes(hexagon, h, h_contact, transition, dim=2)
            gmsh.model.mesh.generate(3)
        except Exception as exc:  # reported on every rank, not only where gmsh runs
            error = f"wrench plate geometry: {exc}"
            gmsh.model.remove()
    msh, facet_tags = _to_mesh(comm, error, gdim=3)
    return Geometry(msh, facet_tags, h=h,
                    description=f"ring wrench plate (G35 outline extruded by {thickness}): head "
                                f"R={head_radius}, hexagon across flats {across_flats}, handle "
                                f"[{handle_start},{handle_end}]x[-{handle_width / 2},"
                                f"{handle_width / 2}], load on x in [{load_start},{handle_end}], "
                                f"rotated {rotation_deg} deg; gmsh h={h}, h_contact={h_contact}")
