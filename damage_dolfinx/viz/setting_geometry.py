"""Where the marks of a setting figure go: outward normals of boundary segments, clamp
hatching, traction arrows (a pull points away from the body, a push ends on it, a shear runs
along it) and evenly spread marker points. Pure NumPy; figstyle.py draws them.
"""
from __future__ import annotations

import numpy as np


def outward_normals(segs, inside, size):
    """Unit normals of boundary segments (nseg, 2, 2) pointing out of the body."""
    d = segs[:, 1] - segs[:, 0]
    length = np.linalg.norm(d, axis=1)[:, None]
    tangent = d / np.where(length > 0, length, 1)
    normal = np.stack([tangent[:, 1], -tangent[:, 0]], 1)
    probe = segs.mean(1) + 0.2 * size * normal
    normal[inside(probe)] *= -1
    return normal


def thin_out(segs, spacing):
    """About one segment per ``spacing`` of boundary length (markers, arrows)."""
    length = np.linalg.norm(segs[:, 1] - segs[:, 0], axis=1)
    return np.diff(np.floor(np.concatenate([[0.0], np.cumsum(length)]) / spacing)) > 0


def support_hatch(segs, inside, size):
    """Short oblique ticks on the outer side of boundary segments (the clamp / foundation
    symbol), about one per 1.5 ``size`` of boundary length."""
    segs = segs[thin_out(segs, 1.5 * size)]
    normal = outward_normals(segs, inside, size)
    tangent = np.stack([-normal[:, 1], normal[:, 0]], 1)
    mid = segs.mean(1)
    return np.stack([mid, mid + size * (normal - 0.6 * tangent)], 1)


def traction_arrows(segs, vectors, inside, size):
    """(tails, deltas) of arrows for a traction on boundary segments, lengths 3 ``size`` x
    |f| / max |f|: a pull starts at the boundary and points away from the body, a push ends on
    it, a mostly tangential (shear) load is drawn along the boundary, just outside it."""
    vectors = np.asarray(vectors, float)
    norm = np.linalg.norm(vectors, axis=1)
    keep = norm > 1e-12 * max(norm.max(initial=0.0), 1e-300)
    segs, vectors, norm = segs[keep], vectors[keep], norm[keep]
    if not len(segs):
        return np.zeros((0, 2)), np.zeros((0, 2))
    deltas = 3 * size * vectors / norm.max()
    mid, normal = segs.mean(1), outward_normals(segs, inside, size)
    cos = np.einsum("ij,ij->i", vectors, normal) / norm
    tails = np.where((cos > 0.5)[:, None], mid, mid - deltas)
    shear = np.abs(cos) <= 0.5
    tails[shear] = mid[shear] + 1.2 * size * normal[shear] - deltas[shear] / 2
    return tails, deltas


def spread(points, spacing):
    """Indices of ``points`` keeping one per square of side ``spacing`` (the one nearest the
    square's centre): evenly spread markers and arrows."""
    points = np.asarray(points, float)
    if not len(points):
        return np.zeros(0, dtype=np.int64)
    rel = (points - points.min(0)) / spacing
    keys = np.floor(rel).astype(np.int64)
    dist = np.linalg.norm(rel - keys - 0.5, axis=1)
    order = np.lexsort((dist, keys[:, 1], keys[:, 0]))
    _, first = np.unique(keys[order], axis=0, return_index=True)
    return np.sort(order[first])
