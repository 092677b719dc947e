"""The history figure of every run (``history.png``): the columns of ``history.csv`` over time,
one small panel per group of columns.

Groups: the damage range (zeta_min, zeta_mean, zeta_max), the iterations (damage, mechanical,
SNES), the step's wall time, each norm alone, and a model's own columns grouped by name
(``contact_force_x``/``_y``/``_z`` together). Columns with no number at all are left out.
Drawn on an explicit ``matplotlib.figure.Figure`` with an Agg canvas inside a local style
context (``figstyle.agg_figure``): the global backend and rcParams of the user's session are
never touched.
Pure matplotlib/numpy (rank 0 calls it).
"""
from __future__ import annotations

import csv
import math
import numpy as np

#: what the fixed columns show (label of the panel, unit)
_LABELS = {"u_L2": ("$L^2$ norm of $u$", ""), "eps_u_L2": ("$L^2$ norm of $\\varepsilon(u)$", ""),
           "zeta": ("damage $\\zeta$ (1 = sound)", ""), "its": ("iterations per step", ""),
           "step_time_s": ("wall time per step", "s")}
_FIXED_GROUPS = [("zeta", ["zeta_min", "zeta_mean", "zeta_max"]), ("u_L2", ["u_L2"]),
                 ("eps_u_L2", ["eps_u_L2"]), ("its", ["damage_its", "mech_its", "snes_its"]),
                 ("step_time_s", ["step_time_s"])]
_COMPONENTS = {"x", "y", "z", "1", "2", "3", "min", "max", "mean", "n", "t"}
_STYLE = {"font.size": 8, "axes.titlesize": 8.5, "figure.titlesize": 10,
          "mathtext.fontset": "dejavusans", "axes.formatter.useoffset": False}


def read_columns(csv_path) -> dict:
    """history.csv as column -> float array (NaN where a value is missing or not a number)."""
    with open(csv_path, newline="") as f:
        rows = list(csv.DictReader(f))

    def number(text):
        try:
            return float(text)
        except (TypeError, ValueError):
            return math.nan
    if not rows:
        return {}
    return {c: np.array([number(r.get(c)) for r in rows]) for c in rows[0] if c is not None}


def column_groups(columns) -> list:
    """[(group name, [columns])] in panel order: the fixed groups, then the model's columns
    grouped by their name without a component suffix."""
    groups, used = [], {"step", "t"}
    for name, members in _FIXED_GROUPS:
        present = [c for c in members if c in columns]
        if present:
            groups.append((name, present))
            used.update(present)
    own = {}
    for c in columns:
        if c in used:
            continue
        head, _, tail = c.rpartition("_")
        key = head if head and tail in _COMPONENTS else c
        own.setdefault(key, []).append(c)
    return groups + list(own.items())


def _own_label(name, cols) -> str:
    """A model column's panel title: its name, or the group's name and its components."""
    if len(cols) == 1:
        return cols[0]
    return f"{name}_" + "/".join(c[len(name) + 1:] for c in cols)


def plot_run_history(csv_path, path, title="", ncols=3) -> list:
    """Draw ``history.png`` from ``csv_path``; returns the groups drawn."""
    from damage_dolfinx.viz.figstyle import agg_figure, save_agg
    data = read_columns(csv_path)
    t = data.get("t")
    if t is None or not np.isfinite(t).any():
        return []
    groups = [(name, [c for c in cols if np.isfinite(data[c]).any()])
              for name, cols in column_groups(data)]
    groups = [(name, cols) for name, cols in groups if cols]
    if not groups:
        return []
    ncols = min(ncols, len(groups))
    nrows = math.ceil(len(groups) / ncols)
    with agg_figure(_STYLE, figsize=(3.3 * ncols, 2.1 * nrows + 0.5), dpi=150,
                    layout="constrained") as fig:
        axes = fig.subplots(nrows, ncols, squeeze=False, sharex=True)
        for ax, (name, cols) in zip(axes.flat, groups):
            label, unit = _LABELS.get(name, (_own_label(name, cols), ""))
            for c in cols:
                y = data[c]
                keep = np.isfinite(y)
                ax.plot(t[keep], y[keep], lw=1.1, marker="." if keep.sum() < 30 else None,
                        ms=3, label=c if len(cols) > 1 else None)
            ax.set_title(label + (f" [{unit}]" if unit else ""), loc="left")
            if name == "zeta":
                ax.set_ylim(min(0.0, np.nanmin([np.nanmin(data[c]) for c in cols])), 1.05)
            if len(cols) > 1:
                ax.legend(fontsize=6.5, frameon=False, loc="best")
            ax.grid(True, alpha=0.3)
        for ax in axes.flat[len(groups):]:
            ax.set_visible(False)
        for ax in axes[-1]:
            ax.set_xlabel("$t$ [s]")
        for col in range(ncols):  # the last visible panel of each column carries the t axis
            visible = [axes[r, col] for r in range(nrows) if axes[r, col].get_visible()]
            if visible:
                visible[-1].xaxis.set_tick_params(labelbottom=True)
                visible[-1].set_xlabel("$t$ [s]")
        if title:
            fig.suptitle(title)
        save_agg(fig, path)
    return groups
