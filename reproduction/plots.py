"""The report's convergence figures: our errors and the thesis's table values on one log-log
plot against h + k, one line per time step k (thesis: open markers, dashed; ours: filled,
solid; the same colour for the same k), so that the figure the verdict is judged on shows both.
Drawn from the comparison of benchmarks/reproduction/fidelity.py (one entry per thesis table).
"""
from __future__ import annotations

from pathlib import Path


def thesis_beside_ours(entry: dict, path: Path, title: str) -> Path:
    """Write ``path`` (PNG) for one table entry of fidelity.py; returns it."""
    from damage_dolfinx.viz import figstyle
    plt = figstyle.pyplot_styled()
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    ks = sorted({c["k"] for c in entry["cells"]}, reverse=True)
    colours = plt.get_cmap("viridis")([i / max(1, len(ks) - 1) * 0.9 for i in range(len(ks))])
    for k, colour in zip(ks, colours):
        cells = sorted((c for c in entry["cells"] if c["k"] == k), key=lambda c: c["h_plus_k"])
        kept = [c for c in cells if "excluded" not in c]
        ax.plot([c["h_plus_k"] for c in kept], [c["thesis"] for c in kept], "o--", color=colour,
                mfc="white", lw=1, label=f"thesis, k = {k:g}")
        for c in cells:
            if "excluded" in c:  # shown, not joined: left out of the statistics
                ax.plot(c["h_plus_k"], c["thesis"], "x", color="0.3", ms=8,
                        label="thesis cell left out (misprint)")
        ours = [(c["h_plus_k"], c["ours"]) for c in cells if "ours" in c]
        if ours:
            ax.plot(*zip(*ours), "o-", color=colour, lw=1.6, label=f"ours, k = {k:g}")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("h + k")
    ax.set_ylabel("error (max over time)")
    ax.grid(True, which="both", alpha=0.3)
    figstyle.log_tick_labels(ax)  # a log axis over less than two decades gets its 2 and 5 ticks
    ax.set_title(f"{title}\nmedian ratio ours/thesis {entry['ratio_median']:.2g}; rate in h + k: "
                 f"thesis {entry['rate_thesis_common_cells']:.2f}, ours {entry['rate_ours']:.2f}",
                 fontsize=9)
    ax.legend(fontsize=7, ncol=2, loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return path


def note_under(png: Path, text: str, source: Path = None) -> Path:
    """Write ``png`` as ``source`` (default: ``png`` itself) with one line of ``text`` under it
    (what a setting figure draws that its thesis caption does not: reproduction.figures.
    mesh_drawn)."""
    from damage_dolfinx.viz import figstyle
    plt = figstyle.pyplot_styled()  # an application script's pyplot: imread, figure, close
    img = plt.imread(source or png)
    h, w = img.shape[:2]
    dpi, strip = 100, 30
    fig = plt.figure(figsize=(w / dpi, (h + strip) / dpi), dpi=dpi)
    ax = fig.add_axes([0, strip / (h + strip), 1, h / (h + strip)])
    ax.imshow(img)
    ax.axis("off")
    fig.text(0.5, 0.5 * strip / (h + strip), text, ha="center", va="center", fontsize=9,
             color="0.1")
    fig.savefig(png, dpi=dpi)
    plt.close(fig)
    return Path(png)
