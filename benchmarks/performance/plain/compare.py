"""Relative difference of the final u and zeta of a straightforward script (final.npz) and of
the package's run (fields_final.npz), nodes matched by their coordinates.

    python benchmarks/performance/plain/compare.py SCRIPT_DIR RUN_DIR
"""
import sys
from pathlib import Path

import numpy as np


def by_coords(coords, values):
    c = np.round(np.asarray(coords)[:, :2], 10)
    order = np.lexsort((c[:, 1], c[:, 0]))
    return values[order]


def main(script_dir, run_dir):
    a = np.load(Path(script_dir) / "final.npz")
    b = np.load(Path(run_dir) / "fields_final.npz")
    out = {}
    for name in ("u", "zeta"):
        mine = a[name].reshape(len(a["coords"]), -1)
        ours = b[name].reshape(len(b[name + "_coords"]), -1)
        x, y = by_coords(a["coords"], mine), by_coords(b[name + "_coords"], ours)
        out[name] = float(np.abs(x - y).max() / max(np.abs(y).max(), 1e-300))
    print(" ".join(f"{k}: {v:.2e}" for k, v in out.items()))
    return out


if __name__ == "__main__":
    main(*sys.argv[1:3])
