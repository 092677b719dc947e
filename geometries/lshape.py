"""Inverted L ("Gamma" shape) of Section 3.1 Example 3 (docs/models.md, section 3.1), gmsh.

Omega = (0,2)^2 minus [1,2]x[0,1): a column (0,1)x(0,1) under a full-width top (0,2)x(1,2).
Facet tags: GAMMA_D = [0,1]x{0} (clamped foot), GAMMA_C = [1,2]x{1} (underside of the overhang,
resting on the obstacle, gap 0), GAMMA_N = [0,2]x{2} (loaded top), FREE = the other three sides
({1}x[0,1], {2}x[1,2], {0}x[0,2], traction free). Unstructured triangles of size h (default
1/32, i.e. 32 cells per unit length); the model is meshed on rank 0 and distributed.
"""
from damage_dolfinx.geometries import lazy_gmsh as gmsh

from damage_dolfinx import compat
from damage_dolfinx.core.parameters import InputError

from damage_dolfinx.geometries import GAMMA_C, GAMMA_D, GAMMA_N, Geometry, generate_2d, gmsh_session

#: traction-free sides
FREE = 4

#: corners counter-clockwise from the origin, and the tag of the side that starts at each
CORNERS = ((0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (2.0, 1.0), (2.0, 2.0), (0.0, 2.0))
SIDE_TAGS = (GAMMA_D, FREE, GAMMA_C, FREE, GAMMA_N, FREE)


def lshape(comm, h: float = 1.0 / 32.0) -> Geometry:
    if not h > 0 or h > 1.0:
        raise InputError(f"L-shape mesh size h must lie in (0, 1], got h = {h}")
    if comm.rank == 0:
        gmsh_session()
        gmsh.model.add("lshape")
        g = gmsh.model.geo
        points = [g.addPoint(x, y, 0.0, h) for x, y in CORNERS]
        lines = [g.addLine(points[i], points[(i + 1) % len(points)]) for i in range(len(points))]
        surface = g.addPlaneSurface([g.addCurveLoop(lines)])
        g.synchronize()
        gmsh.model.addPhysicalGroup(2, [surface], 1)
        for tag in (GAMMA_D, GAMMA_N, GAMMA_C, FREE):
            gmsh.model.addPhysicalGroup(1, [c for c, t in zip(lines, SIDE_TAGS) if t == tag], tag)
        generate_2d(h)
    msh, _, facet_tags = compat.model_to_mesh(gmsh.model, comm, 0, gdim=2)
    if comm.rank == 0:
        gmsh.model.remove()
    return Geometry(msh, facet_tags, h=h,
                    description=f"inverted L (0,2)^2 minus [1,2]x[0,1), gmsh h = {h:.4g} (G26)")
