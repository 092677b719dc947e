"""Masonry arch bridge (Section 2.1 Example 3, thesis Figure 2.6 without the interfaces), gmsh.

The ring is a circular arch of clear ``span`` and ``rise`` (intrados) and radial ``thickness``; the
default (docs/models.md, section 2.1-collapse) is a semicircular ring with centre-line radius 15/pi
(centre line 15.0 m long), thickness 0.70 m, meshed as an n_r x n_theta mapped grid with n_r =
round(thickness/h), n_theta = round(centre-line length/h), every quadrilateral cut into two
triangles by a fixed diagonal (``structured=True``). At h = 0.05 this is n_r = 14, n_theta = 300:
8400 triangles and 4515 nodes, the counts the thesis states. ``structured=False`` gives an
unstructured triangulation of size h of the same geometry.

Sections are numbered from the left springing: grid line j (j = 0..n_theta) is the radial segment
at polar angle theta_j = theta_left - j*dtheta about the centre of the circles.

Facet tags: GAMMA_D = clamped faces (both springing faces; the abutment bases when abutments are
on), GAMMA_N = the load patch (extrados facets within +-load_half_width of the quarter-span
abscissa, or the same patch on the road surface when the fill is on), FREE = all other exterior
faces (traction free). Cell tags: RING, FILL, ABUTMENT. Fill and abutments are off by default
(the thesis's ring has none) and need ``structured=False``. The model is meshed on rank 0 and
distributed.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from damage_dolfinx.geometries import lazy_gmsh as gmsh
import numpy as np

from damage_dolfinx import compat
from damage_dolfinx.core.parameters import InputError

from damage_dolfinx.geometries import GAMMA_D, GAMMA_N, Geometry, generate_2d, gmsh_session

#: traction-free exterior faces
FREE = 4
#: cell tags
RING, FILL, ABUTMENT = 1, 2, 3

#: defaults: centre-line radius 15/pi, thickness 0.70 -> intrados radius 4.4246 m
THICKNESS = 0.70
RADIUS_CENTRE = 15.0 / math.pi
SPAN = 2.0 * (RADIUS_CENTRE - THICKNESS / 2.0)
RISE = SPAN / 2.0


@dataclass
class ArchGeometry(Geometry):
    """A :class:`Geometry` plus the polar grid of the ring (used by the failure criterion)."""
    centre: tuple = (0.0, 0.0)
    r_in: float = 0.0
    r_out: float = 0.0
    theta_left: float = math.pi       # polar angle of the left springing face (section j = 0)
    dtheta: float = 0.0               # angular step between sections
    n_r: int = 0
    n_theta: int = 0
    structured: bool = True
    x_load: float = 0.0               # abscissa of the load (quarter span)
    load_half_width: float = 0.05
    load_surface: str = "extrados"    # "extrados" or "road" (with fill)
    options: dict = field(default_factory=dict)

    def polar(self, x: np.ndarray):
        """(r, theta) of points x (N, >=2) about the centre, theta in (-pi/2, 3pi/2] so that
        both springings (theta ~ 0 and ~ pi, whatever the sign of round-off) are continuous."""
        d = x[:, :2] - np.asarray(self.centre)
        theta = np.arctan2(d[:, 1], d[:, 0])
        return np.hypot(d[:, 0], d[:, 1]), np.where(theta <= -np.pi / 2, theta + 2 * np.pi, theta)

    def section_index(self, x: np.ndarray) -> np.ndarray:
        """Nearest section j = round((theta_left - theta)/dtheta) of points x (N, >=2)."""
        _, theta = self.polar(x)
        return np.rint((self.theta_left - theta) / self.dtheta).astype(np.int64)

    def in_ring(self, x: np.ndarray, tol: float = 1e-8) -> np.ndarray:
        """Mask of the points of x (N, >=2) that lie in the ring (closed)."""
        r, theta = self.polar(x)
        t = tol * self.r_out
        return ((r >= self.r_in - t) & (r <= self.r_out + t)
                & (theta <= self.theta_left + tol) & (theta >= self.theta_left
                                                      - self.n_theta * self.dtheta - tol))

    def section_points(self, j) -> dict:
        """Centre-line point, abscissa s along the centre line from the left springing (m),
        and angle from the left springing (degrees) of sections j."""
        j = np.asarray(j, dtype=float)
        theta = self.theta_left - j * self.dtheta
        rc = 0.5 * (self.r_in + self.r_out)
        return {"x": self.centre[0] + rc * np.cos(theta), "y": self.centre[1] + rc * np.sin(theta),
                "s": rc * j * self.dtheta, "angle_deg": np.degrees(j * self.dtheta)}


def arch_dimensions(span: float, rise: float, thickness: float) -> dict:
    """Intrados circle through the springings (+-span/2, 0) and the crown (0, rise)."""
    if not (span > 0 and rise > 0 and thickness > 0):
        raise InputError(f"arch span, rise and thickness must be positive, got span = {span}, "
                         f"rise = {rise}, thickness = {thickness}")
    if rise > span / 2 + 1e-12:
        raise InputError(f"rise {rise} > span/2 = {span / 2}: only circular arches up to a "
                         f"semicircle are supported")
    r_in = (span**2 / 4 + rise**2) / (2 * rise)
    yc = rise - r_in
    theta0 = math.atan2(-yc, span / 2)  # polar angle of the right springing
    return {"r_in": r_in, "r_out": r_in + thickness, "yc": yc,
            "theta_left": math.pi - theta0, "theta_right": theta0}


def arch_bridge(comm, h: float = 0.05, span: float = SPAN, rise: float = RISE,
                thickness: float = THICKNESS, structured: bool = True, load_fraction: float = 0.25,
                load_half_width: float = 0.05, diagonal: str = "Right", fill: bool = False,
                cover: float = 0.3, abutments: bool = False,
                abutment_height: float = 1.0) -> ArchGeometry:
    """Mesh of the arch ring (the defaults); see the module docstring for tags and options."""
    dims = arch_dimensions(span, rise, thickness)
    if not h > 0 or not 0 < load_fraction < 1 or not load_half_width > 0:
        raise InputError(f"need h > 0, 0 < load_fraction < 1, load_half_width > 0; got h = {h}, "
                         f"load_fraction = {load_fraction}, load_half_width = {load_half_width}")
    if (fill or abutments) and structured:
        raise InputError("fill and abutments need structured=False (unstructured mesh)")
    if diagonal not in ("Left", "Right", "AlternateLeft", "AlternateRight"):
        raise InputError(f"diagonal must be Left, Right, AlternateLeft or AlternateRight, got {diagonal!r}")
    angle = dims["theta_left"] - dims["theta_right"]
    rc = dims["r_in"] + thickness / 2
    n_r = max(1, int(round(thickness / h)))
    n_theta = max(2, int(round(rc * angle / h)))
    dtheta = angle / n_theta
    x_load = -span / 2 + load_fraction * span
    geo = ArchGeometry(mesh=None, facet_tags=None, h=h, centre=(0.0, dims["yc"]),
                       r_in=dims["r_in"], r_out=dims["r_out"], theta_left=dims["theta_left"],
                       dtheta=dtheta, n_r=n_r, n_theta=n_theta, structured=structured,
                       x_load=x_load, load_half_width=load_half_width,
                       load_surface="road" if fill else "extrados",
                       options=dict(span=span, rise=rise, thickness=thickness, fill=fill,
                                    cover=cover, abutments=abutments,
                                    abutment_height=abutment_height, diagonal=diagonal))
    if comm.rank == 0:
        gmsh_session()
        gmsh.model.add("arch_bridge")
        _build_model(geo, diagonal, fill, cover, abutments, abutment_height)
        generate_2d(geo.h)
    geo.mesh, _, geo.facet_tags = compat.model_to_mesh(gmsh.model, comm, 0, gdim=2)
    if comm.rank == 0:
        gmsh.model.remove()
    kind = (f"structured {n_r} x {n_theta} grid ({diagonal} diagonals)" if structured
            else f"unstructured, h = {h}")
    geo.description = (f"circular arch ring, span {span:.4g} m, rise {rise:.4g} m, thickness "
                       f"{thickness:.4g} m (r_in {dims['r_in']:.4g} m), {kind}; load patch "
                       f"x = {x_load:.4g} +- {load_half_width} m on the {geo.load_surface}"
                       + (", with fill" if fill else "") + (", with abutments" if abutments else ""))
    return geo



def _patch_sections(geo: ArchGeometry):
    """(j_a, j_b): the extrados grid facets j_a..j_b-1 whose midpoints lie within x_load +- w;
    at least the facet that contains x_load."""
    j = np.arange(geo.n_theta)
    mid = geo.theta_left - (j + 0.5) * geo.dtheta
    x_mid = geo.centre[0] + geo.r_out * np.cos(mid) * np.cos(geo.dtheta / 2)
    inside = np.flatnonzero(np.abs(x_mid - geo.x_load) <= geo.load_half_width + 1e-12)
    if inside.size == 0:
        inside = np.array([int(np.argmin(np.abs(x_mid - geo.x_load)))])
    return int(inside.min()), int(inside.max()) + 1


def _angle_at_x(geo: ArchGeometry, r: float, x: float) -> float:
    return math.acos(max(-1.0, min(1.0, (x - geo.centre[0]) / r)))


def _build_model(geo: ArchGeometry, diagonal, fill, cover, abutments, abutment_height):
    """Points, arcs and (transfinite) sector surfaces of the ring; fill/abutments if asked."""
    g = gmsh.model.geo
    xc, yc = geo.centre
    centre = g.addPoint(xc, yc, 0.0)
    # break angles of the ring: springings, the load patch (extrados), arcs shorter than pi
    if geo.structured:
        ja, jb = _patch_sections(geo)
        breaks = sorted({0, ja, jb, geo.n_theta // 2, geo.n_theta})
        thetas = [geo.theta_left - j * geo.dtheta for j in breaks]
    else:
        thetas = [geo.theta_left, math.pi / 2, geo.theta_left - geo.n_theta * geo.dtheta]
        if not fill:
            w = geo.load_half_width
            thetas += [_angle_at_x(geo, geo.r_out, geo.x_load - w),
                       _angle_at_x(geo, geo.r_out, geo.x_load + w)]
        thetas = sorted(set(thetas), reverse=True)
        breaks = None

    def polar(r, t):
        return g.addPoint(xc + r * math.cos(t), yc + r * math.sin(t), 0.0, geo.h)

    p_in = [polar(geo.r_in, t) for t in thetas]
    p_out = [polar(geo.r_out, t) for t in thetas]
    radial = [g.addLine(a, b) for a, b in zip(p_in, p_out)]
    arc_in = [g.addCircleArc(p_in[i], centre, p_in[i + 1]) for i in range(len(thetas) - 1)]
    arc_out = [g.addCircleArc(p_out[i], centre, p_out[i + 1]) for i in range(len(thetas) - 1)]
    ring = []
    for i in range(len(thetas) - 1):
        loop = g.addCurveLoop([arc_in[i], radial[i + 1], -arc_out[i], -radial[i]])
        ring.append(g.addPlaneSurface([loop]))
    ext_patch = []
    if geo.structured:
        for line in radial:
            g.mesh.setTransfiniteCurve(line, geo.n_r + 1)
        for i, s in enumerate(ring):
            n_j = breaks[i + 1] - breaks[i]
            g.mesh.setTransfiniteCurve(arc_in[i], n_j + 1)
            g.mesh.setTransfiniteCurve(arc_out[i], n_j + 1)
            g.mesh.setTransfiniteSurface(s, diagonal, [p_in[i], p_in[i + 1], p_out[i + 1], p_out[i]])
        ext_patch = [arc_out[i] for i in range(len(breaks) - 1)
                     if ja <= breaks[i] and breaks[i + 1] <= jb]
    elif not fill:
        lo = _angle_at_x(geo, geo.r_out, geo.x_load + geo.load_half_width)
        hi = _angle_at_x(geo, geo.r_out, geo.x_load - geo.load_half_width)
        ext_patch = [arc_out[i] for i in range(len(thetas) - 1)
                     if lo - 1e-12 <= 0.5 * (thetas[i] + thetas[i + 1]) <= hi + 1e-12]
    clamped, free, load = [radial[0], radial[-1]], list(arc_in), list(ext_patch)
    free += [c for c in arc_out if c not in ext_patch]
    fill_s, abut_s = [], []
    if fill:
        fill_s, road_free, road_load = _add_fill(geo, g, p_out, arc_out, thetas, cover)
        free = [c for c in free if c not in arc_out] + road_free
        load = road_load
    if abutments:
        abut_s, base, sides = _add_abutments(geo, g, p_in, p_out, radial, abutment_height)
        clamped, free = base, free + sides
    g.synchronize()
    gmsh.model.addPhysicalGroup(2, ring, RING)
    if fill_s:
        gmsh.model.addPhysicalGroup(2, fill_s, FILL)
    if abut_s:
        gmsh.model.addPhysicalGroup(2, abut_s, ABUTMENT)
    gmsh.model.addPhysicalGroup(1, clamped, GAMMA_D)
    gmsh.model.addPhysicalGroup(1, load, GAMMA_N)
    gmsh.model.addPhysicalGroup(1, free, FREE)


def _add_fill(geo, g, p_out, arc_out, thetas, cover):
    """Spandrel fill between the extrados, two vertical walls above the extrados springing
    points and a horizontal road at ``cover`` above the crown, split at the crown (x = 0);
    the load patch is on the road."""
    xc, yc = geo.centre
    y_road = yc + geo.r_out + cover
    i_crown = thetas.index(math.pi / 2)
    x_l = xc + geo.r_out * math.cos(thetas[0])
    x_r = xc + geo.r_out * math.cos(thetas[-1])
    w = geo.load_half_width
    xs = sorted({x_l, geo.x_load - w, geo.x_load + w, xc, x_r})
    road_pts = [g.addPoint(x, y_road, 0.0, geo.h) for x in xs]
    road = [g.addLine(road_pts[i], road_pts[i + 1]) for i in range(len(xs) - 1)]
    k_crown = xs.index(xc)
    wall_l = g.addLine(p_out[0], road_pts[0])
    wall_r = g.addLine(p_out[-1], road_pts[-1])
    crown = g.addLine(p_out[i_crown], road_pts[k_crown])
    left = g.addCurveLoop([wall_l] + road[:k_crown] + [-crown]
                          + [-a for a in arc_out[:i_crown]][::-1])
    right = g.addCurveLoop([crown] + road[k_crown:] + [-wall_r]
                           + [-a for a in arc_out[i_crown:]][::-1])
    surfaces = [g.addPlaneSurface([left]), g.addPlaneSurface([right])]
    load = [road[i] for i in range(len(xs) - 1)
            if abs(0.5 * (xs[i] + xs[i + 1]) - geo.x_load) < w]
    free = [c for c in road if c not in load] + [wall_l, wall_r]
    return surfaces, free, load


def _add_abutments(geo, g, p_in, p_out, radial, height):
    """A quadrilateral pier below each springing face: vertical sides from the springing
    points down to a horizontal base (clamped)."""
    surfaces, base, sides = [], [], []
    gmsh.model.geo.synchronize()
    for k, (a, b) in enumerate(((p_in[0], p_out[0]), (p_in[-1], p_out[-1]))):
        xa, ya, _ = gmsh.model.getValue(0, a, [])
        xb, yb, _ = gmsh.model.getValue(0, b, [])
        y0 = min(ya, yb) - height
        qa, qb = g.addPoint(xa, y0, 0.0, geo.h), g.addPoint(xb, y0, 0.0, geo.h)
        side_a, bottom, side_b = g.addLine(a, qa), g.addLine(qa, qb), g.addLine(qb, b)
        line = radial[0] if k == 0 else radial[-1]
        surfaces.append(g.addPlaneSurface([g.addCurveLoop([side_a, bottom, side_b, -line])]))
        base.append(bottom)
        sides += [side_a, side_b]
    return surfaces, base, sides
