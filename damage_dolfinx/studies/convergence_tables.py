"""The products of a convergence study: fitted rates, the Markdown/CSV error tables, the plot."""
from __future__ import annotations


import numpy as np

from damage_dolfinx.viz import post

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


def plot_convergence(path, rows, rates, example_id, ref_n, ref_k, definition="error"):
    from damage_dolfinx.viz import figstyle
    fig, ax = figstyle.plt().subplots(figsize=(6.4, 4.6))
    ks = sorted({r["k"] for r in rows}, reverse=True)
    for k in ks:
        sel = sorted((r for r in rows if r["k"] == k), key=lambda r: r["h_plus_k"])
        ax.loglog([r["h_plus_k"] for r in sel], [r["error"] for r in sel], "o-", ms=4,
                  label=f"$k$ = {k:g}")
    hk = np.array([r["h_plus_k"] for r in rows])
    err = np.array([r["error"] for r in rows])
    p = rates["h_plus_k_all"]
    c = np.exp(np.mean(np.log(err) - p * np.log(hk)))
    xs = np.array([hk.min(), hk.max()])
    ax.loglog(xs, c * xs**p, "k--", label=f"fit: rate {p:.2f}")
    ax.set_xlabel("$h + k$")
    ax.set_ylabel(figstyle.error_mathtext(definition))
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    figstyle.log_tick_labels(ax)
    figstyle.save(fig, path, title=f"{example_id}: convergence (reference $n$ = {ref_n}, "
                  f"$k$ = {ref_k:g})")
