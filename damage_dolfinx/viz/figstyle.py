"""One figure style for every PNG of the package (thesis figures, histories, settings).

Rules, each applied here and nowhere else:

* damage on a fixed colour scale [zeta*, 1] -- never autoscaled -- with the label
  "zeta (1 = sound, zeta* = fully damaged)"; if the field leaves that range (the PDE damage law of
  Section 2.1 can undershoot) the scale widens to [min, max] and the title prints the extremes;
* stresses on a shared scale within a thesis pair (:func:`shared_limits`, used when a pair is
  re-rendered from the saved panel data, see :func:`save_panels` / :func:`render_saved`);
* amplification factors are round (1, 2, 5 x 10^k, or the factor the thesis states) and written
  in the title; a factor below 1 is titled "shrunk";
* deformed-mesh figures: mesh edges of the deformed body over the dashed undeformed outline,
  no colour field (:func:`render_fields` with ``mesh_only``);
* tight layouts, colour bars exactly as tall as their axes, mathtext labels (Gamma_D -> Γ_D, ...).

Pure matplotlib/numpy: no dolfinx here (post.py gathers the data and calls these functions).
What is drawn on a body (figbody.py), the saved panel data (figpanels.py) and the setting
figures (figsetting.py) are modules of their own, reached through this one as well
(``figstyle.draw_field``, ``figstyle.save_panels``, ``figstyle.draw_setting``).
"""
from __future__ import annotations

import contextlib
import math
import re

import numpy as np

from . import fastdraw
from .figscales import (NARROW_DAMAGE, SI_PREFIXES, damage_limits, damage_ticks,  # noqa: F401
                        range_decimals, is_damage, narrow_damage, range_text, shared_limits,
                        si_unit)
from .figtext import (THESIS_FACTORS, amplification_text, drawn_amplification,  # noqa: F401
                      error_mathtext, is_round, mathtext, round_amplification)
from .figbody import (READABLE, RASTERISE_CELLS, _triangulation, boundary_edges,  # noqa: F401
                      draw_field, draw_guides, draw_mesh_edges, draw_outline, readable,
                      triangle_edges, triangle_path)
from .setting_geometry import (outward_normals, spread, support_hatch,  # noqa: F401
                               thin_out, traction_arrows)

#: suffix of the panel data written beside a field figure (figure_2_1.png -> figure_2_1.panel.npz)
PANEL_SUFFIX = ".panel.npz"

DPI = 150
DAMAGE_CMAP = "viridis"        # dark = low zeta = damaged (stated in the colour-bar label)
STRESS_CMAP = "inferno"
DAMAGE_LABEL = "$\\zeta$ (1 = sound,\n$\\zeta^*$ = fully damaged)"


#: the style of every figure, applied inside :func:`styled` (matplotlib.rc_context), never to
#: the global rcParams (laid out as saved: text extents measured once)
STYLE = {"font.size": 9, "axes.titlesize": 9.5, "figure.titlesize": 10.5,
         "mathtext.fontset": "dejavusans", "axes.formatter.useoffset": False, "figure.dpi": DPI}


# ---------------------------------------------------------------------------- drawing
def styled(draw):
    """``draw`` (a function that makes and saves figures) run inside the style
    (``matplotlib.rc_context(STYLE)``): the user's rcParams and backend are untouched."""
    import functools

    @functools.wraps(draw)
    def run(*args, **kwargs):
        import matplotlib
        with matplotlib.rc_context(STYLE):
            return draw(*args, **kwargs)
    return run


class _Figures:
    """The part of pyplot the package uses, without pyplot: figures are
    ``matplotlib.figure.Figure`` objects on their own Agg canvas (no backend is selected, no
    figure manager keeps them, the user's open figures and backend stay as they are)."""

    _SUBPLOT_KEYS = ("sharex", "sharey", "squeeze", "width_ratios", "height_ratios",
                     "subplot_kw", "gridspec_kw")

    @staticmethod
    def figure(**kwargs):
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
        fig = Figure(**kwargs)
        FigureCanvasAgg(fig)
        return fig

    def subplots(self, nrows=1, ncols=1, **kwargs):
        sub = {key: kwargs.pop(key) for key in self._SUBPLOT_KEYS if key in kwargs}
        fig = self.figure(**kwargs)
        return fig, fig.subplots(nrows, ncols, **sub)

    @staticmethod
    def close(fig):
        fig.clear()

    @staticmethod
    def get_cmap(name):
        import matplotlib
        return matplotlib.colormaps[name] if hasattr(matplotlib, "colormaps") else \
            matplotlib.cm.get_cmap(name)

    @property
    def rcParams(self):  # noqa: N802 (pyplot's name) - the values in force (the style inside styled)
        import matplotlib
        return matplotlib.rcParams


_FIGURES = _Figures()


def plt():
    """Figures without pyplot (:class:`_Figures`: ``subplots``, ``figure``, ``close``,
    ``get_cmap``); draw inside :func:`styled` for the package's style."""
    return _FIGURES


def pyplot_styled():
    """For an application script (the reproduction, the benchmarks), not the library: pyplot
    on the Agg backend with the style in the global rcParams."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as pyplot
    pyplot.rcParams.update(STYLE)
    return pyplot


def ticker():
    """matplotlib's tick locators and formatters (for plots laid out outside this module)."""
    import matplotlib.ticker
    return matplotlib.ticker


@styled
def save_as_laid_out(fig, path, dpi=300):
    """Save a figure whose layout and title its caller set (tight bounding box), and close it."""
    fig.savefig(path, dpi=dpi, bbox_inches="tight", **fastdraw.png_options(path))
    plt().close(fig)


def data_aspect(xy) -> float:
    """Height / width of the body's bounding box (sizes the figure to the content)."""
    pts = np.asarray(xy).reshape(-1, 2)
    w, h = np.ptp(pts[:, 0]), np.ptp(pts[:, 1])
    return float(np.clip(h / w if w > 0 else 1.0, 0.25, 2.5))


@styled
def new_figure(npanels: int, aspect: float, panel_width: float = 4.2):
    """Figure with ``npanels`` side-by-side axes of the body's aspect ratio (no empty bands)."""
    pyplot = plt()
    width = panel_width * npanels + 0.3
    fig, axes = pyplot.subplots(1, npanels, figsize=(width, panel_width * aspect + 0.9),
                                squeeze=False)
    return fig, list(axes[0])


def colorbar(fig, ax, mappable, label, ticks=None):
    """A colour bar exactly as tall as ``ax``."""
    from mpl_toolkits.axes_grid1 import make_axes_locatable
    cax = make_axes_locatable(ax).append_axes("right", size="4.5%", pad=0.06)
    cb = fig.colorbar(mappable, cax=cax, ticks=ticks)
    cb.set_label(label, fontsize=8.5)
    cb.ax.tick_params(labelsize=7.5)
    return cb


def plain_ticks(axis, scale=1.0):
    """Tick labels ``value / scale`` written out in full (``%g``): no offset, no multiplier."""
    from matplotlib.ticker import FuncFormatter
    axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v / scale:.4g}"))


def _frame(ax, xy_list):
    pts = np.concatenate([np.asarray(x).reshape(-1, 2) for x in xy_list])
    lo, hi = pts.min(0), pts.max(0)
    pad = 0.03 * max(hi - lo)
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal")
    ax.set_xlabel(r"$x_1$ [m]")
    ax.set_ylabel(r"$x_2$ [m]")


@styled
def render_fields(panels, path, title="", amplification=1.0, ref_xy=None, zeta_star=None,
                  mesh_only=False, limits=None, guides=None):
    """Draw the panels of one figure. ``panels``: list of dicts with ``xy`` (nc, 3, 2) deformed
    triangles, ``values`` (nc, 3) P1 or (nc,) DG0, ``name`` and ``label``. ``limits``: optional
    {panel index: (vmin, vmax)} (shared pair scales). A panel's optional ``title`` replaces the
    default one; mesh-only figures draw one panel (the fields share the deformed body) unless
    every panel has a title (distinct bodies, e.g. undamaged and damaged runs side by side).
    Returns the colour limits used per panel (None for a mesh-only panel)."""
    pyplot = plt()
    panels, amplification, replaced = readable(panels, ref_xy, amplification)
    nplot = len(panels) if not mesh_only or all("title" in p for p in panels) else 1
    allxy = [p["xy"] for p in panels] + ([ref_xy] if ref_xy is not None else [])
    outline = boundary_edges(np.asarray(ref_xy)) if ref_xy is not None else None  # once
    extra = 0 if mesh_only or zeta_star is None else sum(
        is_damage(p.get("name", ""), p.get("label", ""))
        and narrow_damage(float(np.nanmin(p["values"])), float(np.nanmax(p["values"])), zeta_star)
        for p in panels[:nplot])
    fig, axes = new_figure(nplot + extra, data_aspect(np.concatenate(
        [np.asarray(x).reshape(-1, 2) for x in allxy])))
    used, notes, stretched = [], [], []
    for i, ax in enumerate(axes[:nplot]):
        p = panels[i]
        xy, vals = np.asarray(p["xy"]), np.asarray(p["values"])
        if mesh_only:
            draw_mesh_edges(ax, xy)
            ax.set_title(p.get("title", "deformed mesh and undeformed outline (dashed)"))
            used.append(None)
        else:
            tri = _triangulation(xy)
            damage = is_damage(p.get("name", ""), p.get("label", ""))
            if damage and zeta_star is not None:
                vmin, vmax, note = damage_limits(vals, zeta_star)
                cmap, label = DAMAGE_CMAP, DAMAGE_LABEL
                notes.append(note)
            else:
                vmin, vmax = (limits or {}).get(i) or (0.0, float(np.nanmax(vals)) or 1.0)
                cmap, label, note = STRESS_CMAP, mathtext(p.get("label", "")), ""
            im = draw_field(ax, tri, vals, cmap, vmin, vmax)
            ticks = (damage_ticks(vmin, vmax, zeta_star) if damage and zeta_star is not None
                     else None)
            label, scale = si_unit(label, vmax) if not damage else (label, 1.0)
            cb = colorbar(fig, ax, im, label, ticks)
            if not ticks:
                plain_ticks(cb.ax.yaxis, scale)
            if damage:
                lo, hi = float(np.nanmin(vals)), float(np.nanmax(vals))
                faint = zeta_star is not None and narrow_damage(lo, hi, zeta_star)
                if faint:  # the range of the field, on the fixed bar
                    cb.ax.axhspan(lo, hi, xmin=0, xmax=1, facecolor="none", edgecolor="red", lw=1.2)
                ax.set_title(p.get("title", "damage $\\zeta$") + (f"\n{note}" if note else
                             f"\n$\\zeta$ in {range_text(lo, hi)}"),
                             color="firebrick" if note else "k")
                if faint:
                    stretched.append((ax, tri, vals, lo, hi))
            else:
                ax.set_title(p.get("title", re.sub(r"\s*\[[^]]*\]$", "", label)))
            used.append((vmin, vmax))
        if ref_xy is not None:
            draw_outline(ax, None, edges=outline)
        draw_guides(ax, guides, xy, ref_xy)
        _frame(ax, [xy] + ([ref_xy] if ref_xy is not None else [])
               + [np.asarray(g["line"], float) for g in guides or () if "line" in g])
    for ax, (src, tri, vals, lo, hi) in zip(axes[nplot:], stretched):
        _stretched_damage(fig, ax, tri, vals, lo, hi)
        if ref_xy is not None:
            draw_outline(ax, None, edges=outline)
        ax.set_xlim(src.get_xlim())
        ax.set_ylim(src.get_ylim())
        ax.set_aspect("equal")
        ax.set_xlabel(src.get_xlabel())
    full = mathtext(title) + f" — {amplification_text(amplification)}{replaced}"
    fig.tight_layout()
    suptitle_on_top(fig, full)
    fig.savefig(path, dpi=DPI, bbox_inches=_tight(fig), **fastdraw.png_options(path))
    pyplot.close(fig)
    return used


def _stretched_damage(fig, ax, tri, vals, lo, hi):
    """The same damage field on a colour scale stretched to its own range [lo, hi]."""
    im = draw_field(ax, tri, vals, STRETCHED_CMAP, lo, hi)
    cb = colorbar(fig, ax, im, "$\\zeta$ (scale: range of the field)")
    from matplotlib.ticker import FuncFormatter, MaxNLocator
    digits = range_decimals(lo, hi)
    cb.ax.yaxis.set_major_locator(MaxNLocator(4))
    cb.ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:.{digits}f}"))
    ax.set_title(f"the same damage, colours stretched\nto its range {range_text(lo, hi)}")


#: colour map of the stretched damage panel: the damage's own (one colour map per field); its
#: colour bar and title say that the scale is the field's range
STRETCHED_CMAP = DAMAGE_CMAP


def suptitle_on_top(fig, text):
    """The figure title just above the axes' titles (equal-aspect axes shrink inside their
    slot; a default suptitle would float over an empty band)."""
    renderer = fig.canvas.get_renderer()  # no draw first: get_tightbbox applies the aspect
    # and updates the ticks itself (a full draw here doubled the text layout work)
    inv = fig.transFigure.inverted()
    top = max(ax.get_tightbbox(renderer).transformed(inv).y1 for ax in fig.axes)
    fig.suptitle(text, y=top + 0.01, va="bottom")


def log_tick_labels(ax):
    """Label the 2 and 5 minor ticks of log axes spanning less than two decades (a log axis with
    a single labelled power of ten cannot be read)."""
    from matplotlib.ticker import FuncFormatter
    for axis, (lo, hi) in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
        if axis.get_scale() != "log" or lo <= 0 or math.log10(hi / lo) >= 2:
            continue
        axis.set_minor_formatter(FuncFormatter(
            lambda v, _: f"{v:g}" if round(v / 10 ** math.floor(math.log10(v) + 1e-9)) in (2, 5)
            else ""))
        axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))


def LineCollection(segments, **kwargs):
    """matplotlib's LineCollection of ``segments`` (imported on first use)."""
    from matplotlib.collections import LineCollection as collection
    return collection(segments, **kwargs)


def legend_below(ax, ncol=3):
    """Legend under the axes' x label (never over the mesh), at a fixed distance in points
    whatever the axes' height."""
    from matplotlib.transforms import offset_copy
    handles, labels = ax.get_legend_handles_labels()
    if handles:
        ax.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, 0.0), ncol=ncol,
                  bbox_transform=offset_copy(ax.transAxes, fig=ax.figure, y=-34, units="points"),
                  fontsize=8, frameon=False)


def _tight(fig):
    return fastdraw.tight_bbox(fig, plt().rcParams["savefig.pad_inches"])


@styled
def save(fig, path, title=None):
    fig.tight_layout()
    if title:
        suptitle_on_top(fig, title)
    fig.savefig(path, dpi=DPI, bbox_inches=_tight(fig), **fastdraw.png_options(path))
    plt().close(fig)


#: names defined in figpanels.py and figsetting.py, reached through this module too
_ELSEWHERE = {**dict.fromkeys(("save_panels", "load_panels", "render_saved", "render_pair",
                               "render_shared"), "figpanels"),
              **dict.fromkeys(("LOAD_COLOURS", "inside_test", "body_force_points", "draw_arrows",
                               "_split_parts", "_free_edges", "draw_setting"), "figsetting")}


def __getattr__(name):
    if name in _ELSEWHERE:  # imported on first use: those modules import this one
        import importlib
        return getattr(importlib.import_module(f"{__package__}.{_ELSEWHERE[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


# ------------------------------------------------- figures that leave the session alone
@contextlib.contextmanager
def agg_figure(style: dict, **figure_kwargs):
    """An explicit ``matplotlib.figure.Figure`` on its own Agg canvas, created and drawn inside
    ``matplotlib.rc_context(style)``: the session's backend and global rcParams are never
    touched (no pyplot). Save it with :func:`save_agg` inside the ``with`` block."""
    import matplotlib
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    with matplotlib.rc_context(style):
        fig = Figure(**figure_kwargs)
        FigureCanvasAgg(fig)
        yield fig


def save_agg(fig, path):
    """Write a figure made by :func:`agg_figure` (its folder created if needed)."""
    from pathlib import Path
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
