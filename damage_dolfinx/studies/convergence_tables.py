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


#: a journal column (88 mm) and the height of the plot
COLUMN_WIDTH_IN, PLOT_HEIGHT_IN = 3.46, 2.9


@styled
def plot_convergence(path, rows, rates, example_id, ref_n, ref_k, definition="error",
                     title=None):
    """log-log error against h + k for a journal column: one line per time step, a tick and a
    label at every level (h + k of every cell), the axes named with their quantities and the
    error's norms, the fitted slope of all cells drawn (dashed, with its value), the slope in h
    at the smallest k dotted, and a title naming the problem and the norm."""
    from damage_dolfinx.viz import figstyle
    tk = figstyle.ticker()
    FixedLocator, NullFormatter, NullLocator = tk.FixedLocator, tk.NullFormatter, tk.NullLocator
    pyplot = figstyle.plt()
    fig, ax = pyplot.subplots(figsize=(COLUMN_WIDTH_IN, PLOT_HEIGHT_IN))
    ks = sorted({r["k"] for r in rows}, reverse=True)
    for k in ks:
        sel = sorted((r for r in rows if r["k"] == k), key=lambda r: r["h_plus_k"])
        ax.loglog([r["h_plus_k"] for r in sel], [r["error"] for r in sel], "o-", ms=3.5, lw=1,
                  label=f"$k$ = {k:g}")
    hk = np.array([r["h_plus_k"] for r in rows])
    err = np.array([r["error"] for r in rows])
    p = rates["h_plus_k_all"]
    if np.isfinite(p):
        c = np.exp(np.mean(np.log(err) - p * np.log(hk)))
        xs = np.array([hk.min(), hk.max()])
        ax.loglog(xs, c * xs**p, "k--", lw=1, label=f"fit, all cells: slope {p:.2f}")
    col = sorted((r for r in rows if r["k"] == min(ks)), key=lambda r: r["h_plus_k"])
    q = rates.get("h_at_smallest_k", float("nan"))
    if len(col) > 1 and np.isfinite(q):
        x = np.array([r["h_plus_k"] for r in col])
        e = np.array([r["error"] for r in col])
        c = np.exp(np.mean(np.log(e) - q * np.log(x)))
        ax.loglog(x, 0.7 * c * x**q, ":", color="0.35", lw=1.2,
                  label=f"slope in $h$ at $k$ = {min(ks):g}: {q:.2f}")
    levels = np.unique(np.round(hk, 12))
    ax.xaxis.set_major_locator(FixedLocator(levels))
    ax.xaxis.set_minor_locator(NullLocator())
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xticks(levels)
    labels, last = [], None
    for v in levels:  # a tick at every level; a label where it does not overlap the previous
        show = last is None or np.log10(v / last) > 0.07
        labels.append(f"{v:.3g}" if show else "")
        last = v if show else last
    ax.set_xticklabels(labels, rotation=60, fontsize=7)
    ax.set_xlabel("mesh size + time step, $h + k$ (length + time units)", fontsize=8)
    norms = figstyle.error_mathtext(definition)
    ax.set_ylabel(f"error {norms}", fontsize=8)
    ax.tick_params(axis="y", labelsize=7)
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize=6, loc="lower right", framealpha=0.85)
    figstyle.log_tick_labels(ax)
    FixedFormatter = tk.FixedFormatter
    ax.xaxis.set_major_locator(FixedLocator(levels))
    ax.xaxis.set_major_formatter(FixedFormatter(labels))
    ax.xaxis.set_minor_formatter(NullFormatter())
    lo, hi = ax.get_ylim()
    if hi / lo < 10:  # less than a decade: a label at every tick of the error axis
        FuncFormatter, LogLocator = tk.FuncFormatter, tk.LogLocator
        ax.yaxis.set_minor_locator(LogLocator(subs=np.arange(1, 10)))
        ax.yaxis.set_minor_formatter(FuncFormatter(lambda v, _: f"{v:.2g}"))
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:.2g}"))
        ax.tick_params(axis="y", which="minor", labelsize=7)
    name = title or example_id
    fig.tight_layout()
    ax.set_title(f"{name}\nconvergence in {norms}\nreference $n$ = {ref_n}, $k$ = {ref_k:g}",
                 fontsize=7.5)
    figstyle.save_as_laid_out(fig, path)
