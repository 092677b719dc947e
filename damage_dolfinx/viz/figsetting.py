"""Setting figures: the undeformed mesh with its boundary parts (supports hatched, parts
split where a quantity changes), the traction-free outline and the load arrows."""
from __future__ import annotations

import numpy as np

from . import fastdraw
from .figtext import mathtext
from .figstyle import (LineCollection, _frame, boundary_edges, legend_below,
                       triangle_edges)
from .setting_geometry import spread, support_hatch, traction_arrows

LOAD_COLOURS = {"f_N": "tab:purple", "f_B": "tab:orange"}


def inside_test(cells):
    """``inside(points) -> bool array``: points inside the body whose triangles are ``cells``."""
    return fastdraw.inside_test(cells)


def body_force_points(cells, spacing):
    """Points of a regular grid of step ``spacing`` inside the body (where the body-force
    arrows sit); for thin bodies that the grid misses, one cell centroid per square."""
    cells = np.asarray(cells)
    pts = cells.reshape(-1, 2)
    lo, hi = pts.min(0), pts.max(0)
    gx, gy = (np.arange(lo[i] + spacing / 2, hi[i], spacing) for i in range(2))
    grid = np.stack([g.ravel() for g in np.meshgrid(gx, gy)], 1)
    grid = grid[inside_test(cells)(grid)]
    if len(grid) >= 4:
        return grid
    centroids = cells.mean(1)
    return centroids[spread(centroids, spacing / 2)]


def draw_arrows(ax, tails, deltas, colour, label, size):
    if not len(tails):
        return
    for i, (p, d) in enumerate(zip(tails, deltas)):
        ax.annotate("", xy=p + d, xytext=p, zorder=4,
                    arrowprops=dict(arrowstyle="-|>", color=colour, lw=1.1,
                                    mutation_scale=8 + 4 * min(1.0, np.linalg.norm(d) / (3 * size))))
    ax.plot([], [], color=colour, lw=1.1, marker=">", markersize=4, label=label)  # legend entry


def _split_parts(parts, split):
    """Boundary parts divided where a quantity changes along them (``split``: {label: (name,
    function of the segment midpoints)}), e.g. the two friction planes of one contact part."""
    out = []
    for segs, colour, label, hatched in parts:
        if not split or label not in split or segs.size == 0:
            out.append((segs, colour, label, hatched))
            continue
        name, fn = split[label]
        values = np.asarray(fn(segs.mean(1)), float)
        for i, v in enumerate(np.unique(values)):
            out.append((segs[values == v], colour, f"{label}, {name} = {v:g}", hatched,
                        ("solid", "dashed", "dotted")[i % 3]))
    return out


def _free_edges(cells, parts):
    """Outline edges of the mesh that no boundary part covers: traction-free."""
    edges = boundary_edges(np.asarray(cells))
    if not len(edges):
        return edges
    covered = [p[0].reshape(-1, 2, 2) for p in parts if p[0].size]
    if not covered:
        return edges
    key = lambda segs: {tuple(sorted((tuple(np.round(a, 7)), tuple(np.round(b, 7)))))  # noqa: E731
                        for a, b in segs}
    taken = set().union(*(key(c) for c in covered))
    return np.array([e for e in edges if tuple(sorted((tuple(np.round(e[0], 7)),
                                                       tuple(np.round(e[1], 7))))) not in taken])


def draw_setting(ax, cells, parts, loads=(), note="", split=None):
    """A thesis setting figure: the undeformed mesh, boundary parts (``parts``: (segments,
    colour, label, hatched)), load arrows (``loads``: ("f_N", segments, vectors, label) or
    ("f_B", points, vectors, label)); frames the axes on body, markers and arrows; ``note``
    (e.g. why a load is not drawn) goes under the legend. Outline edges no part covers are
    drawn as traction-free; ``split`` divides a part where a quantity changes along it."""
    cells = np.asarray(cells)
    triangle_edges(ax, cells, colour="0.6", zorder=1,
                              linewidth=0.3 if len(cells) > 3000 else 0.5)
    size = 0.025 * max(np.ptp(cells.reshape(-1, 2), axis=0))
    inside = inside_test(cells)
    extent = [cells.reshape(-1, 2) + s for s in (-2 * size, 2 * size)]
    free = _free_edges(cells, parts)
    if len(free):
        ax.add_collection(LineCollection(free, colors="k", linewidths=1.4,  # solid: dashes
                                         label="traction-free boundary", zorder=3))  # restart per facet
    for segs, colour, label, hatched, *style in _split_parts(parts, split):
        if segs.size == 0:
            continue
        ax.add_collection(LineCollection(segs, colors=colour, linewidths=2.2,
                                         linestyles=style[0] if style else "solid",
                                         label=mathtext(label), zorder=3))
        if hatched:
            ax.add_collection(LineCollection(support_hatch(segs, inside, size), colors=colour,
                                             linewidths=0.8, zorder=3))
    for kind, where, vectors, label in loads:
        where, vectors = np.asarray(where, float), np.asarray(vectors, float)
        if kind == "f_N":
            tails, deltas = traction_arrows(where, vectors, inside, size)
        else:
            norm = np.linalg.norm(vectors, axis=1)
            deltas = 2.5 * size * vectors / max(norm.max(initial=0.0), 1e-300)
            tails = where - deltas / 2
        draw_arrows(ax, tails, deltas, LOAD_COLOURS[kind], label, size)
        extent += [tails, tails + deltas]
    _frame(ax, extent)
    legend_below(ax, ncol=2)
    if note:
        ax.annotate(note, xy=(0.5, 0.0), xycoords="axes fraction", xytext=(0, -62),
                    textcoords="offset points", ha="center", va="top", fontsize=7.5,
                    color="0.3")
