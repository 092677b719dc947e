"""What is drawn on a body: its triangles' edges, a field on them, its outline, and the guides
beside it (obstacle and friction planes, marked points), with the rule that keeps an amplified
deformation readable.

Pure matplotlib/numpy; reached through :mod:`figstyle` as well (``figstyle.draw_field``).
"""
from __future__ import annotations

import numpy as np

from . import fastdraw
from .figtext import round_amplification

# ---------------------------------------------------------------------------- primitives
# One matplotlib object per layer, never one per cell (a 10^5-cell mesh as 10^5 Path objects
# takes seconds to build and draw). Edges: every triangle's outline in one Path (interior
# edges stroked twice, as when each triangle was its own polygon). Fields: Gouraud-shaded
# triangles in one draw call; a DG0 value is given to its triangle's three corners (the soup
# has its own vertices per cell), so the triangle has the one colour of its value, as a flat
# tripcolor polygon would. Large layers are rasterised in vector output.
#: cells above which a layer is rasterised in vector output
RASTERISE_CELLS = 3000


def triangle_path(xy):
    """One Path of the outlines of the triangles ``xy`` (nc, 3, 2)."""
    from matplotlib.path import Path
    xy = np.asarray(xy, dtype=float)
    nc = xy.shape[0]
    verts = np.concatenate([xy, xy[:, :1]], axis=1).reshape(-1, 2)
    codes = np.tile(np.array([Path.MOVETO, Path.LINETO, Path.LINETO, Path.CLOSEPOLY],
                             dtype=Path.code_type), nc)
    return Path(verts, codes)


def triangle_edges(ax, xy, colour="k", linewidth=0.35, zorder=2):
    """The edges of the triangles ``xy`` (nc, 3, 2) as one PathPatch; returns it."""
    from matplotlib.patches import PathPatch
    patch = PathPatch(triangle_path(xy), facecolor="none", edgecolor=colour,
                      linewidth=linewidth, zorder=zorder, joinstyle="miter", capstyle="butt")
    patch.set_rasterized(len(xy) > RASTERISE_CELLS)
    fastdraw.out_of_layout(patch)
    ax.add_artist(patch)  # add_patch would walk the 10^5 segments for the data limits
    ax.update_datalim(np.asarray(xy, dtype=float).reshape(-1, 2))
    return patch


def draw_field(ax, tri, values, cmap, vmin, vmax):
    """The field ``values`` (nc, 3) P1 or (nc,) DG0 on the soup triangulation ``tri`` (three
    vertices of its own per cell) as one Gouraud-shaded collection; returns the mappable."""
    values = np.asarray(values, dtype=float)
    per_vertex = values.reshape(-1) if values.ndim == 2 else np.repeat(values, 3)
    from matplotlib.collections import TriMesh
    # what ax.tripcolor(shading="gouraud") does, without its add_collection(autolim=True), which
    # converts the mesh to one Path per triangle only to find the data limits
    im = TriMesh(tri, array=per_vertex, cmap=cmap)
    im.set_clim(vmin, vmax)
    im.set_rasterized(len(per_vertex) // 3 > RASTERISE_CELLS)
    fastdraw.out_of_layout(im)
    ax.grid(False)
    ax.update_datalim([(tri.x.min(), tri.y.min()), (tri.x.max(), tri.y.max())])
    ax.autoscale_view()
    ax.add_collection(im, autolim=False)
    return im


def boundary_edges(xy):
    """Edges of a triangle soup (nc, 3, 2) that belong to one triangle only (the outline)."""
    edges = np.concatenate([xy[:, [0, 1]], xy[:, [1, 2]], xy[:, [2, 0]]])
    a, b = np.round(edges[:, 0], 9), np.round(edges[:, 1], 9)
    swap = ((a[:, 0] > b[:, 0]) | ((a[:, 0] == b[:, 0]) & (a[:, 1] > b[:, 1])))[:, None]
    key = np.hstack([np.where(swap, b, a), np.where(swap, a, b)])
    # one lexsort of the four coordinates (np.unique(axis=0) sorts rows as objects: slower)
    order = np.lexsort(key.T[::-1])
    ks = key[order]
    new = np.ones(len(ks) + 1, dtype=bool)
    new[1:-1] = np.any(ks[1:] != ks[:-1], axis=1)
    starts = np.flatnonzero(new)
    single = starts[:-1][np.diff(starts) == 1]
    return edges[order[single]]


def draw_outline(ax, ref_xy, label="undeformed outline", edges=None):
    """The outline of ``ref_xy`` (``edges``: its boundary_edges, when already computed)."""
    from matplotlib.collections import LineCollection
    edges = boundary_edges(ref_xy) if edges is None else edges
    ax.add_collection(LineCollection(edges, colors="tab:red", linewidths=0.8,
                                     linestyles="--", label=label, zorder=3))


def draw_mesh_edges(ax, xy, lw=None):
    lw = lw or (0.35 if len(xy) < 3000 else 0.2)
    triangle_edges(ax, xy, colour="k", linewidth=lw, zorder=2)


def _triangulation(xy):
    import matplotlib.tri as mtri
    pts = xy.reshape(-1, 2)
    return mtri.Triangulation(pts[:, 0], pts[:, 1], np.arange(pts.shape[0]).reshape(-1, 3))


#: the drawn (amplified) largest displacement stays below this fraction of the body's diameter,
#: so that the drawn body stays within about 1.5 times its size
READABLE = 0.5


def readable(panels, ref_xy, amplification):
    """(panels, factor, note): the panels redrawn with a factor that keeps the drawn largest
    displacement below READABLE of the body's diameter (the automatic 10 %, rounded) when the
    factor asked for (a thesis's) would not; ``note`` says which factor was replaced."""
    if ref_xy is None or not amplification:
        return panels, amplification, ""
    ref = np.asarray(ref_xy, float)
    size = float(np.hypot(*np.ptp(ref.reshape(-1, 2), axis=0)))
    drawn = max(float(np.max(np.linalg.norm(np.asarray(p["xy"], float) - ref, axis=-1)))
                for p in panels)
    if size == 0 or drawn <= READABLE * size:
        return panels, amplification, ""
    umax = drawn / amplification
    factor = round_amplification(0.1 * size / umax)
    scaled = [dict(p, xy=ref + (np.asarray(p["xy"], float) - ref) * (factor / amplification))
              for p in panels]
    return scaled, factor, (f"\n(the ×{amplification:g} asked for would draw |u| at "
                            f"{drawn / size:.2g}× the body's size)")


def draw_guides(ax, guides, xy=None, ref_xy=None):
    """What the thesis's figure draws beside the body: obstacle and friction planes (``line``:
    two end points, drawn as a thick grey line with its label) and marked points (``point``:
    an undeformed position, drawn where that material point is in the drawn configuration:
    the hinges of the arch)."""
    for g in guides or ():
        if "line" in g:
            (x0, y0), (x1, y1) = g["line"]
            ax.plot([x0, x1], [y0, y1], color="0.35", lw=3.0, solid_capstyle="butt", zorder=4)
        elif "point" in g:
            p = np.asarray(g["point"], float)
            if xy is not None and ref_xy is not None:
                ref = np.asarray(ref_xy, float).reshape(-1, 2)
                p = np.asarray(xy, float).reshape(-1, 2)[np.argmin(np.linalg.norm(ref - p, axis=1))]
            ax.plot(*p, marker="o", ms=7, mfc="none", mec="red", mew=1.6, zorder=5)
            centre = np.mean(ax.get_xlim()), np.mean(ax.get_ylim())
            if xy is not None:
                pts = np.asarray(xy, float).reshape(-1, 2)
                centre = (pts.min(0) + pts.max(0)) / 2
            inward = np.asarray(centre) - p
            inward = 11 * inward / max(np.linalg.norm(inward), 1e-300)
            ax.annotate(g.get("mark", ""), xy=p, fontsize=7, color="red", xytext=inward,
                        textcoords="offset points", ha="center", va="center", zorder=5)
    lines = [g["label"] for g in guides or () if "line" in g and g.get("label")]
    notes = [g["note"] for g in guides or () if g.get("note")] + \
        ([f"grey line{'s' if len(lines) > 1 else ''}: " + "; ".join(lines)] if lines else [])
    if notes:  # under the x label, never over the body
        ax.annotate("; ".join(dict.fromkeys(notes)), xy=(0.5, 0.0), xycoords="axes fraction",
                    xytext=(0, -36), textcoords="offset points", ha="center", va="top",
                    fontsize=7, color="0.2")
