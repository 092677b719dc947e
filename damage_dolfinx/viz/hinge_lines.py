"""Figures of the barrel vault's collapse (example 2.1-ex3-vault): the hinge lines and
the load-displacement curve.

* ``plot_hinge_lines``: the damage zeta on the extrados and on the intrados, unrolled (abscissa
  s along the centre line from the left springing, z across the width), one node per grid point
  (section j, layer l) of each face, on the fixed damage scale [zeta*, 1] of figstyle; below,
  the section damage D_j (mean over the section plane) along the ring with the hinges (peaks of
  D_j) marked: filled if they rotate in the collapse step (the mechanism), open otherwise.
  A hinge line is a dark band across the whole width of a face.
* ``plot_load_displacement``: P [kN per metre of width] against the downward displacement of the
  loaded strip, the collapse point marked; optionally a reference curve (the 2-D arch).
"""
from __future__ import annotations

import csv
import math

import numpy as np
from mpi4py import MPI

from damage_dolfinx.viz import figstyle
from damage_dolfinx.viz.figstyle import styled


def vault_summary(stepper) -> dict:
    """The "vault" part of summary.json of a 3-D bridge run (problems/bridge_2_1.py): width,
    the total load, and at collapse D per (section, layer), the unrolled faces and the section
    rotations of the collapse step."""
    geo, f = stepper.data.geometry, stepper.failure

    def at_failure(key):
        return None if f is None else f[key]
    return {
        "width_m": stepper.width, "n_width": geo.n_width, "ends": geo.ends,
        "load": "P_kN is the line load per metre of width; total = P_kN x width_m",
        "failure_load_total_kN": None if f is None else f["P_kN"] * stepper.width,
        "nodes_per_section_layer": [int(stepper._layer_nodes.min()),
                                    int(stepper._layer_nodes.max())],
        "section_s_m": np.round(geo.section_points(np.arange(geo.n_theta + 1))["s"], 4).tolist(),
        "s_load_m": round(0.5 * (geo.r_in + geo.r_out) * (geo.theta_left - math.acos(
            (geo.x_load - geo.centre[0]) / geo.r_out)), 4),
        "failure_zeta_extrados": at_failure("zeta_extrados"),
        "failure_zeta_intrados": at_failure("zeta_intrados"),
        "failure_section_damage_layers": at_failure("section_damage_layers"),
        "failure_section_rotation_step_mrad": at_failure("section_rotation_step_mrad")}


def face_maps(stepper):  # called by problems/bridge_2_1.py at collapse (3-D)
    """(zeta on the intrados, zeta on the extrados), arrays (n_sections, n_layers) on every rank
    (collective): one grid node per (section, layer) of each face."""
    ns, nl = stepper.data.geometry.n_theta + 1, stepper._n_layers
    z = stepper.zeta.x.array[stepper._sec_dofs]
    maps = []
    for mask in (stepper._on_in, stepper._on_out):
        m = np.full(ns * nl, np.inf)
        np.minimum.at(m, stepper._sec_jl[mask], z[mask])
        stepper.comm.Allreduce(MPI.IN_PLACE, m, op=MPI.MIN)
        maps.append(m.reshape(ns, nl))
    return maps


@styled
def plot_hinge_lines(summary, path, title=""):
    """The figure of the module docstring from a run's summary.json (rank 0 only)."""
    vault, bridge = summary["vault"], summary["bridge"]
    if vault.get("failure_zeta_extrados") is None:
        raise ValueError("the run did not collapse: no hinge lines to draw")
    z_out = np.asarray(vault["failure_zeta_extrados"])
    z_in = np.asarray(vault["failure_zeta_intrados"])
    D = np.asarray(summary["failure_section_damage"])
    zs = summary["parameters"]["zeta_star"]
    s = np.asarray(vault["section_s_m"])
    z = np.linspace(0.0, vault["width_m"], z_out.shape[1])
    pyplot = figstyle.plt()
    fig, axes = pyplot.subplots(3, 1, figsize=(8.0, 7.6), sharex=True,
                                gridspec_kw={"height_ratios": [1, 1, 1.2]})
    vmin, vmax, note = figstyle.damage_limits(np.concatenate([z_out.ravel(), z_in.ravel()]), zs)
    s_load = vault["s_load_m"]
    for ax, face, name in ((axes[0], z_out, "extrados"), (axes[1], z_in, "intrados")):
        image = ax.pcolormesh(s, z, face.T, cmap=figstyle.DAMAGE_CMAP, vmin=vmin, vmax=vmax,
                              shading="nearest")
        ax.set_ylabel("$z$ [m]")
        ax.set_title(f"{name}, unrolled" + (f" ({note})" if note else ""), fontsize=9)
        figstyle.colorbar(fig, ax, image, figstyle.DAMAGE_LABEL,
                          ticks=figstyle.damage_ticks(vmin, vmax, zs))
    ax = axes[2]
    ax.plot(s, D, "-", lw=1.2, label="section damage $D_j$ (mean over the plane)")
    ax.axhline(summary["hinge_definition"]["min_height"], ls=":", color="0.5", lw=1,
               label="hinge threshold")
    for h in summary["hinges"]:
        active = h["mechanism"]
        ax.plot(h["s_m"], h["section_damage"], "v", ms=8, color="r" if active else "0.5",
                mfc="r" if active else "none")
        ax.annotate(f"{h['angle_deg']:.0f}°" + (f"\n{h['opening_face']}" if active else ""),
                    (h["s_m"], h["section_damage"]), textcoords="offset points", xytext=(0, 6),
                    ha="center", fontsize=7)
        for a in axes[:2]:
            a.axvline(h["s_m"], color="r" if active else "0.5", lw=0.8, ls="--")
    for a in axes:
        a.axvline(s_load, color="tab:green", lw=1.0)
    ax.plot([], [], color="tab:green", lw=1.0, label="line load")
    ax.plot([], [], "rv", label="hinge line rotating at collapse")
    ax.plot([], [], "v", color="0.5", mfc="none", label="damage peak, not rotating")
    ax.set_ylim(0, 1.5)
    ax.set_ylabel("$D_j$")
    ax.set_xlabel("$s$ along the centre line from the left springing [m]")
    ax.legend(loc="upper center", fontsize=7, ncol=3)
    from mpl_toolkits.axes_grid1 import make_axes_locatable  # same width as the maps above
    blank = make_axes_locatable(ax).append_axes("right", size="4.5%", pad=0.06)
    blank.set_xticks([])
    blank.set_yticks([])
    for spine in blank.spines.values():
        spine.set_visible(False)
    figstyle.save(fig, path, title=title)


@styled
def draw_figure(stepper, fig, path):
    """A catalogue figure of kind "problem" of the bridge stepper (collective; rank 0 draws):
    fig.fields[0] is "hinge_lines" (3-D, at collapse) or "load_displacement" (P against the
    downward displacement of the load patch, from history.csv next to ``path``)."""
    if stepper.comm.rank != 0:
        return
    f = stepper.failure
    if fig.fields[0] == "load_displacement":
        plot_load_displacement(path.parent / "history.csv", None if f is None else f["P_kN"],
                               path, fig.title)
    elif fig.fields[0] == "hinge_lines" and f is not None and stepper._n_layers > 1:
        summary = {**stepper.summary_extra(),
                   "parameters": {"zeta_star": stepper.params.zeta_star}}
        plot_hinge_lines(summary, path, title=f"{fig.title} (P = {f['P_kN']:.4g} kN/m, W = "
                                              f"{stepper.width:g} m)")
    else:  # no collapse (or 2-D): say so instead of leaving the listed file missing
        pyplot = figstyle.plt()
        fig_, ax = pyplot.subplots(figsize=(6.0, 1.6))
        ax.axis("off")
        ax.text(0.5, 0.5, f"no collapse up to t = {stepper.t:.4g} s (P = "
                f"{stepper.load_kN():.4g} kN/m): no hinge lines", ha="center", va="center")
        figstyle.save(fig_, path, title=fig.title)


def read_curve(history_csv):
    """(P [kN/m], downward displacement of the loaded strip [mm]) from history.csv."""
    with open(history_csv) as f:
        rows = list(csv.DictReader(f))
    return (np.array([float(r["P_kN"]) for r in rows]),
            np.array([-1e3 * float(r["u_load_y"]) for r in rows]))


@styled
def plot_load_displacement(history_csv, failure_kN, path, title="", reference=None,
                           label="this run"):
    """P against the downward displacement; ``reference`` = (history_csv, failure_kN, label)
    of another run drawn for comparison (rank 0 only)."""
    pyplot = figstyle.plt()
    fig, ax = pyplot.subplots(figsize=(6.4, 4.2))
    runs = [(history_csv, failure_kN, label, "o-")]
    if reference is not None:
        runs.append((*reference, "s--"))
    for csv_path, fail, name, style in runs:
        P, d = read_curve(csv_path)
        line, = ax.plot(d, P, style, ms=3, label=name)
        if fail is not None:
            ax.plot(d[-1], P[-1], "*", ms=12, color=line.get_color(),
                    label=f"collapse: {fail:.4g} kN/m")
    ax.set_xlabel("downward displacement of the loaded strip [mm]")
    ax.set_ylabel("line load $P$ [kN per m of width]")
    ax.set_ylim(bottom=0)
    ax.set_xlim(left=0)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="lower right", fontsize=8)
    figstyle.save(fig, path, title=title)
