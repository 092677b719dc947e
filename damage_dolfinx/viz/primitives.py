"""Drawing primitives of the field and mesh figures: one matplotlib object per panel layer,
never one per cell (a 10^5-cell mesh as 10^5 Path objects takes seconds to build and draw).

* :func:`triangle_edges`: every triangle's outline as one Path (MOVETO, LINETO, LINETO,
  CLOSEPOLY per triangle) in one PathPatch. Interior edges are stroked twice, as they were
  when each triangle was its own polygon, so the picture is the same.
* :func:`field`: a P1 field (nc, 3) or a DG0 field (nc,) on a triangle soup as Gouraud-shaded
  triangles, one draw call: a DG0 value is given to the triangle's three corners (the soup has
  its own vertices per cell), so the triangle is filled with the one colour of its value, as a
  flat ``tripcolor`` polygon would be.
Large layers are rasterised (vector output stays small).
"""
from __future__ import annotations

import numpy as np

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
    ax.add_artist(patch)  # add_patch would walk the 10^5 segments for the data limits
    ax.update_datalim(np.asarray(xy, dtype=float).reshape(-1, 2))
    return patch


def field(ax, tri, values, cmap, vmin, vmax):
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
    ax.grid(False)
    ax.update_datalim([(tri.x.min(), tri.y.min()), (tri.x.max(), tri.y.max())])
    ax.autoscale_view()
    ax.add_collection(im, autolim=False)
    return im
