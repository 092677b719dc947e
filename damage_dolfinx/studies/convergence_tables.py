"""The products of a convergence study: fitted rates, the Markdown/CSV error tables, the plot."""
from __future__ import annotations


import numpy as np

from damage_dolfinx.viz import post
from damage_dolfinx.viz.figstyle import styled

def fitted_rates(rows, ns, ks, key="error") -> dict:
    """Observed orders of ``key``: in h + k over all cells and over the diagonal (n, k) pairs,
    in h at the smallest k, in k at the finest n."""
    rows = [dict(r, error=r[key]) for r in rows]
    hk = [r["h_plus_k"] for r in rows]
    err = [r["error"] for r in rows]
    k_min, n_max = min(ks), max(ns)
    col = [r for r in rows if r["k"] == k_min]
    row = [r for r in rows if r["n"] == n_max]
    m = min(len(ns), len(ks))
    diag = [r for r in rows if (r["n"], r["k"]) in
            zip(sorted(ns)[-m:], sorted(ks, reverse=True)[-m:])]
    return {"h_plus_k_all": post.loglog_rate(hk, err),
            "h_plus_k_diagonal": post.loglog_rate([r["h_plus_k"] for r in diag],
                                                  [r["error"] for r in diag]),
            "diagonal_pairs": [[r["n"], r["k"]] for r in diag],
            "h_at_smallest_k": post.loglog_rate([r["h"] for r in col], [r["error"] for r in col]),
            "k_at_finest_n": post.loglog_rate([r["k"] for r in row], [r["error"] for r in row])}


def _markdown_table(title, values, ns, ks, rates):
    lines = [title, "", "| n \\ k | " + " | ".join(f"{k:g}" for k in ks) + " |",
             "|---|" + "---|" * len(ks)]
    for n in ns:
        lines.append(f"| {n} | " + " | ".join(f"{values[(n, k)]:.4e}" for k in ks) + " |")
    return lines + ["", f"Observed rate in h + k (all cells): {rates['h_plus_k_all']:.3f}; "
                    f"diagonal pairs {rates['diagonal_pairs']}: {rates['h_plus_k_diagonal']:.3f}; "
                    f"in h at k = {min(ks):g}: {rates['h_at_smallest_k']:.3f}; "
                    f"in k at n = {max(ns)}: {rates['k_at_finest_n']:.3f}", ""]


def write_tables(out, rows, ns, ks, rates, rates_T, example_id, ref_n, ref_k, definition):
    import csv
    with open(out / "errors.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    lines = _markdown_table(
        f"# {example_id}: error {definition}, "
        f"reference n = {ref_n}, k = {ref_k}", {(r["n"], r["k"]): r["error"] for r in rows},
        ns, ks, rates)
    lines += _markdown_table(
        "## Error at the final time T only (shows the time-discretisation error where the "
        "maximum over time is attained at t = 0)",
        {(r["n"], r["k"]): r["error_at_T"] for r in rows}, ns, ks, rates_T)
    (out / "errors.md").write_text("\n".join(lines))


#: a journal column (88 mm) and the height of the plot's axes region
COLUMN_WIDTH_IN, PLOT_HEIGHT_IN = 3.46, 2.9
#: the order of the reference triangle: the schemes' error estimates are linear in h + k
REFERENCE_SLOPE = 1.0


def line_rates(rows) -> dict:
    """{k: slope of log error against log(h + k) along the line of that time step} (the slope
    a reader measures on the plot; NaN for a line of one point)."""
    out = {}
    for k in sorted({r["k"] for r in rows}, reverse=True):
        sel = [r for r in rows if r["k"] == k]
        out[k] = post.loglog_rate([r["h_plus_k"] for r in sel], [r["error"] for r in sel])
    return out


def _slope_text(p) -> str:
    return f"slope {p:.2f}" if np.isfinite(p) else "one level: no slope"


def _level_labels(levels, ax, fontsize):
    """A label at every level of h + k that leaves room for the previous one (labels written
    horizontally, their width estimated from the font size and the axes' width)."""
    width_in = ax.get_position().width * ax.figure.get_figwidth()
    lo, hi = np.log10(levels.min()), np.log10(levels.max())
    per_decade = width_in / max(hi - lo, 1e-12)  # inches per decade of the axis
    labels, last = [], None
    for v in levels:
        text = f"{v:.3g}"
        need = (0.62 * fontsize / 72) * (len(text) + 1.5)  # inches for this label and a gap
        show = last is None or np.log10(v / last) * per_decade > need
        labels.append(text if show else "")
        last = v if show else last
    return labels


def _reference_triangle(ax, hk, lines, slope):
    """A slope triangle of order ``slope`` in the lower right of the axes, under every line
    (``lines``: (x, y) arrays of what is drawn), with its order written beside its vertical
    leg; returns the lowest error it needs visible."""
    lx = np.log10(hk.max() / hk.min())
    x1 = hk.max() / 10 ** (0.06 * lx)
    x0 = x1 / 10 ** (0.3 * lx)
    below = []
    for x, y in lines:
        order = np.argsort(x)
        lxs, lys = np.log10(np.asarray(x)[order]), np.log10(np.asarray(y)[order])
        for xv in np.linspace(np.log10(x0), np.log10(x1), 9):
            if lxs[0] <= xv <= lxs[-1]:
                below.append(np.interp(xv, lxs, lys))
        inside = (lxs >= np.log10(x0)) & (lxs <= np.log10(x1))
        below += list(lys[inside])
    top = 10 ** min(below) * 0.72 if below else None
    if top is None:
        return None
    bottom = top / (x1 / x0) ** slope
    ax.fill([x0, x1, x1], [bottom, bottom, top], facecolor="0.9", edgecolor="0.3", lw=0.8,
            zorder=1)
    ax.text(x1 * 10 ** (0.015 * lx), np.sqrt(bottom * top), f"{slope:g}", fontsize=7,
            va="center", ha="left", color="0.2")
    ax.text(np.sqrt(x0 * x1), bottom / 10 ** 0.01, "1", fontsize=7, va="top", ha="center",
            color="0.2")
    return bottom


@styled
def plot_convergence(path, rows, rates, example_id, ref_n, ref_k, definition="error",
                     title=None):
    """log-log error against h + k for a journal column: one line per time step, its measured
    slope (along the line, in h + k) in the legend; the least-squares fit over all cells
    (dashed, with its slope); a reference triangle of slope 1 (the schemes' estimates are
    linear in h + k); a tick at every level with a label where it fits; the error's norms on
    the y axis; the legend under the axes (never over the data); a title naming the problem
    and the reference."""
    import textwrap
    from damage_dolfinx.viz import figstyle
    tk = figstyle.ticker()
    pyplot = figstyle.plt()
    fig, ax = pyplot.subplots(figsize=(COLUMN_WIDTH_IN, PLOT_HEIGHT_IN))
    slopes = line_rates(rows)
    drawn = []
    for k, slope in slopes.items():
        sel = sorted((r for r in rows if r["k"] == k), key=lambda r: r["h_plus_k"])
        x, y = [r["h_plus_k"] for r in sel], [r["error"] for r in sel]
        ax.loglog(x, y, "o-", ms=3.5, lw=1.1, label=f"$k$ = {k:g}: {_slope_text(slope)}",
                  zorder=3)
        drawn.append((x, y))
    hk = np.array([r["h_plus_k"] for r in rows])
    err = np.array([r["error"] for r in rows])
    p = rates["h_plus_k_all"]
    if np.isfinite(p):
        c = np.exp(np.mean(np.log(err) - p * np.log(hk)))
        xs = np.array([hk.min(), hk.max()])
        ax.loglog(xs, c * xs**p, "k--", lw=0.9, label=f"fit, all cells: slope {p:.2f}",
                  zorder=2)
        drawn.append((xs, c * xs**p))
    if len(np.unique(hk)) > 1:
        bottom = _reference_triangle(ax, hk, drawn, REFERENCE_SLOPE)
        if bottom is not None:
            ax.plot([], [], color="0.3", lw=0.8, marker="^", ms=4, mfc="0.9", ls="none",
                    label=f"reference slope {REFERENCE_SLOPE:g}")
            lo = min(err.min(), bottom)
            ax.set_ylim(lo / 1.25, err.max() * 1.25)
    ax.set_xscale("log")
    ax.set_yscale("log")
    levels = np.unique(np.round(hk, 12))
    span = np.log10(levels.max() / levels.min()) if len(levels) > 1 else 1.0
    ax.set_xlim(levels.min() / 10 ** (0.06 * span), levels.max() * 10 ** (0.06 * span))
    fig.tight_layout()  # the axes' width, for the labels that fit
    ax.xaxis.set_major_locator(tk.FixedLocator(levels))
    ax.xaxis.set_minor_locator(tk.NullLocator())
    ax.xaxis.set_major_formatter(tk.FixedFormatter(_level_labels(levels, ax, 7)))
    ax.tick_params(axis="x", labelsize=7)
    ax.set_xlabel("mesh size + time step, $h + k$", fontsize=8)
    norms = figstyle.error_mathtext(definition)
    ax.set_ylabel(f"error {norms}", fontsize=8)
    ax.tick_params(axis="y", labelsize=7)
    ax.grid(True, which="major", alpha=0.3)
    lo, hi = ax.get_ylim()
    if hi / lo < 10:  # less than a decade: a label at every tick of the error axis
        ax.yaxis.set_minor_locator(tk.LogLocator(subs=np.arange(1, 10)))
        ax.yaxis.set_minor_formatter(tk.FuncFormatter(lambda v, _: f"{v:.2g}"))
        ax.yaxis.set_major_formatter(tk.FuncFormatter(lambda v, _: f"{v:.2g}"))
        ax.tick_params(axis="y", which="minor", labelsize=7)
    else:
        figstyle.log_tick_labels(ax)
    name = "\n".join(textwrap.wrap(title or example_id, 58))
    ax.set_title(f"{name}\nreference $n$ = {ref_n}, $k$ = {ref_k:g}", fontsize=7.5)
    figstyle.legend_below(ax, ncol=2)
    ax.get_legend().set_title(None)
    for text in ax.get_legend().get_texts():
        text.set_fontsize(7)
    figstyle.save_as_laid_out(fig, path)
