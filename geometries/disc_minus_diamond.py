"""Disc |x| < R minus the diamond |x_1| + |x_2| <= a (Section 2.1 Example 2), gmsh.

Gamma_D = diamond boundary (clamped), Gamma_N = circle (docs/models.md, section 2.1). Mesh size h,
refined to h_corner near the four diamond corners. The model is meshed on rank 0 and distributed.
"""
from damage_dolfinx.geometries import lazy_gmsh as gmsh

from damage_dolfinx import compat

from damage_dolfinx.geometries import GAMMA_D, GAMMA_N, Geometry, gmsh_session


def disc_minus_diamond(comm, h: float = 0.1, h_corner: float = 0.05, R: float = 4.0,
                       a: float = 1.0) -> Geometry:
    if comm.rank == 0:
        gmsh_session()
        gmsh.model.add("disc_minus_diamond")
        occ = gmsh.model.occ
        disc = occ.addDisk(0, 0, 0, R, R)
        corners = [occ.addPoint(x, y, 0) for x, y in ((a, 0), (0, a), (-a, 0), (0, -a))]
        lines = [occ.addLine(corners[i], corners[(i + 1) % 4]) for i in range(4)]
        diamond = occ.addPlaneSurface([occ.addCurveLoop(lines)])
        body, _ = occ.cut([(2, disc)], [(2, diamond)])
        occ.synchronize()
        surface = body[0][1]
        # classify boundary curves by bounding box: only the circle is wider than the diamond
        circle, inner = [], []
        for dim, tag in gmsh.model.getBoundary([(2, surface)], oriented=False):
            xmin, ymin, _, xmax, ymax, _ = gmsh.model.getBoundingBox(dim, tag)
            (circle if xmax - xmin > 2 * a + 1e-6 else inner).append(tag)
        gmsh.model.addPhysicalGroup(2, [surface], 1)
        gmsh.model.addPhysicalGroup(1, inner, GAMMA_D)
        gmsh.model.addPhysicalGroup(1, circle, GAMMA_N)
        field = gmsh.model.mesh.field
        dist = field.add("Distance")
        corner_pts = [t for d, t in gmsh.model.getBoundary([(1, c) for c in inner],
                                                           combined=False, oriented=False)]
        field.setNumbers(dist, "PointsList", sorted(set(corner_pts)))
        thr = field.add("Threshold")
        field.setNumber(thr, "InField", dist)
        field.setNumber(thr, "SizeMin", h_corner)
        field.setNumber(thr, "SizeMax", h)
        field.setNumber(thr, "DistMin", 2 * h_corner)
        field.setNumber(thr, "DistMax", 0.5)
        field.setAsBackgroundMesh(thr)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
        gmsh.model.mesh.generate(2)
    msh, _, facet_tags = compat.model_to_mesh(gmsh.model, comm, 0, gdim=2)
    if comm.rank == 0:
        gmsh.model.remove()
    return Geometry(msh, facet_tags, h=h,
                    description=f"disc R={R} minus diamond |x1|+|x2|<={a}, gmsh h={h}, "
                                f"h_corner={h_corner}")
