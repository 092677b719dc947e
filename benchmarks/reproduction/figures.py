"""Regenerate the thesis figures (PNG, named after the thesis figure numbers).

    python benchmarks/reproduction/figures.py [--quick] [--np 2] [--out results/figures] [--only ID ...]

Runs every catalogue example (and its variants) with `damage-dolfinx run` under
`mpirun -n NP`, copies the figures into OUT and writes OUT/index.json (command, status and wall
time of each run). Quick mode: coarse meshes at the thesis time steps; full mode: thesis
resolutions. See reproduction/reproduce.py.

Thesis pairs drawn by different runs or at different times (2.4/2.5, 2.17, 2.20, 2.24/2.25,
3.8) are then re-rendered from their saved panel data on one stress scale (figstyle.render_pair).
"""
import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # benchmarks/: common.py
import common  # noqa: E402,F401  (puts the checkout on sys.path)
from damage_dolfinx.viz import figstyle  # noqa: E402
from reproduction import reproduce  # noqa: E402

#: thesis figures whose two files share one stress (or strain) colour scale
PAIRS = [("figure_2_4.png", "figure_2_5.png"), ("figure_2_17_t0.png", "figure_2_17_t2.png"),
         ("figure_2_20_t0.png", "figure_2_20_t0.5.png"), ("figure_2_24.png", "figure_2_25.png"),
         ("figure_3_8_undamaged.png", "figure_3_8_damaged.png")]


def share_pair_scales(out: Path, index: dict) -> list:
    """Re-render every pair of PAIRS present in ``out`` on shared scales; returns the pairs."""
    done = []
    for pair in PAIRS:
        entries = [next((f for f in index["figures"] if f["file"] == name), None) for name in pair]
        npzs = [_npz(out, index, e) for e in entries]
        if all(npzs):
            figstyle.render_pair(npzs[0], npzs[1], out / pair[0], out / pair[1])
            done.append(pair)
    return done


def _npz(out, index, entry):
    if not entry or not entry.get("source"):
        return None
    run = next((r for r in index["runs"] if r["example"] == entry["example"]
                and r["variant"] == entry["variant"]), None)
    npz = Path(run["folder"]) / Path(entry["source"]).with_suffix(".panel.npz") if run else None
    return npz if npz and npz.is_file() else None


p = argparse.ArgumentParser()
p.add_argument("--quick", action="store_true", help="coarse meshes (minutes)")
p.add_argument("--np", type=int, default=2, help="MPI ranks per run")
p.add_argument("--out", default=None)
p.add_argument("--only", nargs="+", help="example ids")
p.add_argument("--resume", action="store_true",
               help="keep the runs that completed in an earlier invocation into the same OUT")
a = p.parse_args()
mode = "quick" if a.quick else "full"
out = Path(a.out or ("results/figures-quick" if a.quick else "results/figures"))
index = reproduce.run_figures(mode, out, a.np, a.only, a.resume)
shared = share_pair_scales(out, index)
failed = [r for r in index["runs"] if r["returncode"] != 0]
print(f"{len(index['figures'])} figures from {len(index['runs'])} runs in "
      f"{index['wall_time_this_invocation_s']} s (runs: {index['wall_time_s']} s in two lanes) "
      f"({mode} mode, {a.np} ranks) -> {out}; failed runs: {[r['example'] for r in failed] or 'none'}; "
      f"pairs on shared scales: {len(shared)}")
if failed:  # `make figures` fails when a run fails (the index and the report still say which)
    sys.exit(1)
