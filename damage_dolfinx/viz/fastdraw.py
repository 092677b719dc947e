"""What keeps a figure's drawing cost a fraction of a second on 10^5-cell meshes: PNG output
with fast compression, large layers kept out of the layout computation, and a point-in-body
test without a search structure.

Pure matplotlib/numpy (figstyle.py calls these)."""
from __future__ import annotations

import numpy as np

#: zlib level of the PNG files: 1 writes a field figure in a few ms (the default 6 takes
#: several times longer); the pixels are the same, the files up to a third larger
#: (benchmarks/README.md, "Why the defaults")
PNG_COMPRESS_LEVEL = 1


def png_options(path) -> dict:
    """Keyword arguments of ``savefig`` for ``path``: PNG files with PNG_COMPRESS_LEVEL."""
    if str(path).lower().endswith(".png"):
        return {"pil_kwargs": {"compress_level": PNG_COMPRESS_LEVEL}}
    return {}


def out_of_layout(artist):
    """Leave ``artist`` out of tight-layout and tight-bounding-box computations: a mesh or a
    field drawn inside axes whose limits already frame it (matplotlib would otherwise build
    one Path per triangle to measure it)."""
    artist.set_in_layout(False)
    return artist


def inside_test(cells):
    """``inside(points) -> bool array``: points inside (or on) one of the triangles ``cells``
    (nc, 3, 2), by barycentric coordinates against the triangles of the vertical strip around
    each point (cells sorted by their lowest x; the callers ask about a few hundred points at
    most; no search structure to build)."""
    cells = np.asarray(cells, dtype=float).reshape(-1, 3, 2)
    lo_x, hi_x = cells[:, :, 0].min(1), cells[:, :, 0].max(1)
    order = np.argsort(lo_x)
    cells, lo_x, hi_x = cells[order], lo_x[order], hi_x[order]
    width = float((hi_x - lo_x).max()) if len(cells) else 0.0
    a, e1, e2 = cells[:, 0], cells[:, 1] - cells[:, 0], cells[:, 2] - cells[:, 0]
    det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    det = np.where(det == 0, np.inf, det)  # a degenerate triangle contains nothing
    tol = 1e-12

    def inside(points):
        points = np.asarray(points, dtype=float).reshape(-1, 2)
        out = np.zeros(len(points), dtype=bool)
        first = np.searchsorted(lo_x, points[:, 0] - width, side="left")
        last = np.searchsorted(lo_x, points[:, 0], side="right")
        for i, (j0, j1) in enumerate(zip(first, last)):
            d = points[i] - a[j0:j1]
            s = (d[:, 0] * e2[j0:j1, 1] - d[:, 1] * e2[j0:j1, 0]) / det[j0:j1]
            t = (e1[j0:j1, 0] * d[:, 1] - e1[j0:j1, 1] * d[:, 0]) / det[j0:j1]
            out[i] = bool(np.any((s >= -tol) & (t >= -tol) & (s + t <= 1 + tol)))
        return out
    return inside


def tight_bbox(fig, pad_inches):
    """The bounding box that ``savefig(bbox_inches="tight")`` would compute (all the figure's
    artists, padded by ``pad_inches``: rcParams["savefig.pad_inches"]), computed on the
    laid-out figure: handed to savefig as ``bbox_inches``, it spares savefig a draw pass of its
    own to find it."""
    return fig.get_tightbbox(fig.canvas.get_renderer()).padded(pad_inches)
