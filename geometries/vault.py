"""Masonry barrel vault (beyond the thesis): the thesis arch ring (Section 2.1 Example 3;
docs/models.md, section 2.1-collapse) extruded along z by a width W, gmsh, tetrahedra.

The 2-D ring of ``geometries/bridge.py`` (structured n_r x n_theta grid, one fixed diagonal per
quadrilateral; defaults: semicircle, centre-line radius 15/pi, thickness 0.70 m) is extruded by
``width`` in ``n_width`` layers (default round(width/h)); gmsh cuts every prism of a layer into
three tetrahedra. The vault has no fill (the thesis's ring has none, line 1125), so the whole
section is the ring. Every grid node sits at (r_i, theta_j, z_l): a cross-section of the vault is
the plane theta = theta_j, which contains the width direction (n_r + 1) x (n_width + 1) nodes.

Facet tags (gmsh physical surfaces): GAMMA_D = both springing faces (clamped, over the whole
width), GAMMA_N = the loaded strip: the extrados facets of the 2-D load patch (midpoints within
+-load_half_width of the quarter-span abscissa) extruded over the full width, i.e. a line load
across the vault; FREE = intrados and the rest of the extrados; the two end faces z = 0 and
z = W are END (traction free, a free-standing vault) or, with ``ends="plane_strain"``, GAMMA_C
(bilateral, u_z = 0: the middle slice of an infinitely long vault, i.e. plane strain). Cell tag
RING. The model is meshed on rank 0 and distributed.
"""
from __future__ import annotations

from dataclasses import dataclass

from damage_dolfinx.geometries import lazy_gmsh as gmsh
import numpy as np

from damage_dolfinx import compat
from damage_dolfinx.core.parameters import InputError

from damage_dolfinx.geometries import GAMMA_C, GAMMA_D, GAMMA_N, gmsh_session
from damage_dolfinx.geometries.bridge import FREE, RING, SPAN, RISE, THICKNESS, ArchGeometry, _build_model, arch_dimensions

#: traction-free end faces z = 0 and z = W (ends="free")
END = 5
#: values of ``ends``
ENDS = ("free", "plane_strain")


@dataclass
class VaultGeometry(ArchGeometry):
    """An :class:`ArchGeometry` (the polar grid of the ring in the x-y plane) plus the width."""
    width: float = 1.0
    n_width: int = 1
    ends: str = "free"

    def layer_index(self, x):
        """Grid layer l = round(z n_width / width) (0..n_width) of points x (N, 3)."""
        return np.rint(x[:, 2] * self.n_width / self.width).astype(np.int64)


def barrel_vault(comm, h: float = 0.1, width: float = 1.0, n_width: int = None,
                 span: float = SPAN, rise: float = RISE, thickness: float = THICKNESS,
                 load_fraction: float = 0.25, load_half_width: float = 0.05,
                 diagonal: str = "Right", ends: str = "free") -> VaultGeometry:
    """Tetrahedral mesh of the barrel vault; see the module docstring for tags and options."""
    dims = arch_dimensions(span, rise, thickness)
    if not (h > 0 and width > 0 and 0 < load_fraction < 1 and load_half_width > 0):
        raise InputError(f"need h > 0, width > 0, 0 < load_fraction < 1, load_half_width > 0; "
                         f"got h = {h}, width = {width}, load_fraction = {load_fraction}, "
                         f"load_half_width = {load_half_width}")
    if ends not in ENDS:
        raise InputError(f"ends must be one of {', '.join(ENDS)}, got ends = {ends!r}")
    n_width = max(1, int(round(width / h))) if n_width is None else int(n_width)
    if n_width < 1:
        raise InputError(f"n_width must be >= 1, got n_width = {n_width}")
    angle = dims["theta_left"] - dims["theta_right"]
    rc = dims["r_in"] + thickness / 2
    n_r = max(1, int(round(thickness / h)))
    n_theta = max(2, int(round(rc * angle / h)))
    geo = VaultGeometry(mesh=None, facet_tags=None, h=h, centre=(0.0, dims["yc"]),
                        r_in=dims["r_in"], r_out=dims["r_out"], theta_left=dims["theta_left"],
                        dtheta=angle / n_theta, n_r=n_r, n_theta=n_theta, structured=True,
                        x_load=-span / 2 + load_fraction * span, load_half_width=load_half_width,
                        load_surface="extrados", width=width, n_width=n_width, ends=ends,
                        options=dict(span=span, rise=rise, thickness=thickness, width=width,
                                     n_width=n_width, ends=ends, diagonal=diagonal))
    if comm.rank == 0:
        gmsh_session()
        gmsh.model.add("barrel_vault")
        _build_vault(geo, diagonal)
        gmsh.model.mesh.generate(3)
    geo.mesh, _, geo.facet_tags = compat.model_to_mesh(gmsh.model, comm, 0, gdim=3)
    if comm.rank == 0:
        gmsh.model.remove()
    geo.description = (f"barrel vault: circular arch ring (span {span:.4g} m, rise {rise:.4g} m, "
                       f"thickness {thickness:.4g} m, r_in {dims['r_in']:.4g} m) extruded by "
                       f"{width:.4g} m; structured {n_r} x {n_theta} x {n_width} grid, 3 "
                       f"tetrahedra per prism ({diagonal} diagonals); line load strip x = "
                       f"{geo.x_load:.4g} +- {load_half_width} m on the extrados across the "
                       f"width; ends {ends}")
    return geo


def _build_vault(geo: VaultGeometry, diagonal: str):
    """The structured 2-D ring of bridge.py (its 1-D physical groups say which curves are the
    springing faces and the load patch), extruded by the width in n_width layers; every lateral
    surface is found as the surface adjacent to its 2-D curve that is not a bottom surface."""
    _build_model(geo, diagonal, False, 0.3, False, 1.0)  # fill, cover, abutments: none
    model = gmsh.model
    clamped = list(model.getEntitiesForPhysicalGroup(1, GAMMA_D))
    loaded = list(model.getEntitiesForPhysicalGroup(1, GAMMA_N))
    bottom = [int(s) for s in model.getEntitiesForPhysicalGroup(2, RING)]
    model.removePhysicalGroups()
    out = model.geo.extrude([(2, s) for s in bottom], 0.0, 0.0, geo.width,
                            numElements=[geo.n_width], recombine=False)
    model.geo.synchronize()
    volumes = [t for d, t in out if d == 3]
    top = [out[i - 1][1] for i, (d, _) in enumerate(out) if d == 3]  # the entry before each volume

    def lateral(curves):
        return sorted({int(s) for c in curves for s in model.getAdjacencies(1, c)[0]
                       if s not in bottom})

    d_faces, n_faces = lateral(clamped), lateral(loaded)
    boundary = {t for _, t in model.getBoundary([(3, v) for v in volumes], combined=True,
                                                oriented=False)}
    ends = set(bottom) | set(top)
    free = sorted(boundary - ends - set(d_faces) - set(n_faces))
    model.addPhysicalGroup(3, volumes, RING)
    model.addPhysicalGroup(2, d_faces, GAMMA_D)
    model.addPhysicalGroup(2, n_faces, GAMMA_N)
    model.addPhysicalGroup(2, free, FREE)
    model.addPhysicalGroup(2, sorted(ends), GAMMA_C if geo.ends == "plane_strain" else END)
