"""Figures of 3-D runs: fields sampled on plane sections through the body.

Each field (von Mises, damage) is evaluated on a regular grid of points in a coordinate plane
(``compat.locate_points`` + ``Function.eval``, in parallel: every rank evaluates the points in
its cells, rank 0 combines), points outside the body are left blank. The style rules of
figstyle.py apply: damage on the fixed scale [zeta*, 1] (widened and noted if the field leaves
it), one stress scale for all sections of a field, colour bars as tall as their axes.
"""
from __future__ import annotations

import numpy as np
from mpi4py import MPI

from damage_dolfinx import compat
from damage_dolfinx.viz import figstyle
from damage_dolfinx.viz.figstyle import styled

#: sample points per side of a section
RESOLUTION = 161
AXES = "xyz"


def sample_plane(fn, axis: int, value: float, lo, hi, res=RESOLUTION):
    """On rank 0: (s, t, values (res, res)) of the scalar Function ``fn`` on the plane
    x_axis = value over the box [lo, hi] (NaN outside the body); s, t are the coordinates of
    the two other axes (increasing). None on the other ranks."""
    a, b = [i for i in range(3) if i != axis]
    # pixel centres, shifted by different fractions in s and t so that no sample lies on a mesh
    # face (grid planes, diagonals): a cell-wise field is two-valued there, and which cell is
    # found first depends on the partition (serial and parallel figures would differ)
    s = lo[a] + (np.arange(res) + 0.5137) * (hi[a] - lo[a]) / res
    t = lo[b] + (np.arange(res) + 0.4729) * (hi[b] - lo[b]) / res
    S, T = np.meshgrid(s, t)
    points = np.zeros((S.size, 3))
    points[:, a], points[:, b], points[:, axis] = S.ravel(), T.ravel(), value
    msh = fn.function_space.mesh
    cells = compat.locate_points(msh, points)
    found = np.flatnonzero(cells >= 0)
    local = np.full(S.size, np.nan)
    if found.size:
        local[found] = fn.eval(points[found], cells[found]).reshape(found.size, -1)[:, 0]
    gathered = msh.comm.gather(local, root=0)
    if msh.comm.rank != 0:
        return None
    stacked = np.vstack(gathered)
    values = np.full(S.size, np.nan)
    for row in stacked:  # the first rank that found a point gives its value
        missing = np.isnan(values)
        values[missing] = row[missing]
    return s, t, values.reshape(S.shape)


#: a body whose smallest extent is below this fraction of its largest is a plate: one section
THIN = 0.2


def default_planes(msh):
    """Sections through the middle of the bounding box: z = mid (horizontal), y = mid, moved by
    1e-7 of the extent so that a section on a face of the mesh shows the cells on one side of it
    (cell-wise fields are two-valued on a face). A plate (smallest extent < THIN x largest, e.g.
    the wrench plate) gets its mid-plane only: the other sections would be thin strips."""
    lo, hi = _bounds(msh)
    mid = 0.5 * (lo + hi) + 1e-7 * (hi - lo)
    extent = hi - lo
    if extent.min() < THIN * extent.max():
        axis = int(np.argmin(extent))
        return [(axis, float(mid[axis]))]
    return [(2, float(mid[2])), (1, float(mid[1]))]


def _bounds(msh):
    x = msh.geometry.x
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    msh.comm.Allreduce(x.min(axis=0) if x.size else lo.copy(), lo, op=MPI.MIN)
    msh.comm.Allreduce(x.max(axis=0) if x.size else hi.copy(), hi, op=MPI.MAX)
    return lo, hi


@styled
def plot_slices(fields, path, title="", zeta_star=0.01, planes=None, msh=None):
    """PNG of ``fields`` [(Function, label), ...] (rows) on ``planes`` [(axis, value), ...]
    (columns). Collective; rank 0 draws. Returns the planes drawn."""
    msh = msh or fields[0][0].function_space.mesh
    planes = planes or default_planes(msh)
    lo, hi = _bounds(msh)
    samples = [[sample_plane(fn, axis, value, lo, hi) for axis, value in planes]
               for fn, _ in fields]
    # the extremes of the whole body, which the sections may miss (printed in the titles)
    owned = [fn.x.array[:fn.function_space.dofmap.index_map.size_local] for fn, _ in fields]
    body_min = [msh.comm.allreduce(float(v.min()) if v.size else np.inf, op=MPI.MIN) for v in owned]
    body_max = [msh.comm.allreduce(float(v.max()) if v.size else -np.inf, op=MPI.MAX) for v in owned]
    if msh.comm.rank != 0:
        return planes
    pyplot = figstyle.plt()
    fig, axes = pyplot.subplots(len(fields), len(planes), squeeze=False,
                                figsize=(4.4 * len(planes) + 0.4, 3.9 * len(fields) + 0.6))
    for row, ((fn, label), rows) in enumerate(zip(fields, samples)):
        damage = figstyle.is_damage(fn.name, label)
        every = np.concatenate([v.ravel() for _, _, v in rows])
        if damage:
            vmin, vmax, note = figstyle.damage_limits(every[~np.isnan(every)], zeta_star)
            cmap, cbar_label = figstyle.DAMAGE_CMAP, figstyle.DAMAGE_LABEL
        else:  # the scale covers the whole body, so sections compare with its maximum
            vmin, vmax, note = 0.0, body_max[row], ""
            cmap, cbar_label = figstyle.STRESS_CMAP, figstyle.mathtext(label)
        for col, ((axis, value), (s, t, v)) in enumerate(zip(planes, rows)):
            ax = axes[row][col]
            a, b = [AXES[i] for i in range(3) if i != axis]
            image = ax.pcolormesh(s, t, np.ma.masked_invalid(v), cmap=cmap, vmin=vmin,
                                  vmax=vmax, shading="nearest")
            ax.set_xlim(lo["xyz".index(a)], hi["xyz".index(a)])
            ax.set_ylim(lo["xyz".index(b)], hi["xyz".index(b)])
            ax.set_aspect("equal")
            ax.set_xlabel(f"${a}$ [m]")
            ax.set_ylabel(f"${b}$ [m]")
            heading = f"{figstyle.mathtext(label)}, section ${AXES[axis]}$ = {value:.4g}"
            extreme = (f"whole body: min {_damage_value(body_min[row])}" if damage
                       else f"whole body: max {body_max[row]:.3g}")
            ax.set_title(heading + f"\n{extreme}" + (f"; {note}" if note else ""))
            ticks = figstyle.damage_ticks(vmin, vmax, zeta_star) if damage else None
            figstyle.colorbar(fig, ax, image, cbar_label, ticks=ticks)
    figstyle.save(fig, path, title=title)
    return planes


def _damage_value(z) -> str:
    """min zeta for a title: 3 digits, more when it is within 1e-3 of 1 (0.99986, not '1')."""
    return f"{z:.3g}" if z < 0.999 or z >= 1.0 else f"{z:.6f}".rstrip("0")
