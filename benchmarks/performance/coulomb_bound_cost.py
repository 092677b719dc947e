"""The per-step cost of a friction bound of the state against a constant bound of the same value.

    python benchmarks/performance/coulomb_bound_cost.py [--pairs 8] [--n 8] [--T 0.5]

The Coulomb demo's block (demos/demo_coulomb_friction.py) slides at f_x = 4 > mu q, once with
the Coulomb bound g = mu p_nu(u_{n-1}) (evaluated at the contact nodes at the start of every
friction solve) and once with the constant bound mu q, the value the Coulomb bound has there
(the foundation is preloaded: p_nu = q from the start). The runs alternate (C, K, K, C, ...) in
one process; the measure of a run is the median of history.csv's step_time_s (its first step
left out). Printed: per pair the two medians and their ratio, then the median ratio and the
median per-step difference in microseconds. Record: reference_output/coulomb_friction/bound_cost.md.
"""
import argparse
import csv
import runpy
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
import common  # noqa: E402,F401  (the checkout on sys.path)

import damage_dolfinx as dd  # noqa: E402


def median_step(folder) -> float:
    with open(Path(folder) / "history.csv") as f:
        rows = list(csv.DictReader(f))
    return float(np.median([float(r["step_time_s"]) for r in rows[2:]]))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=8)
    parser.add_argument("--n", type=int, default=8)
    parser.add_argument("--T", type=float, default=0.5)
    args = parser.parse_args()
    demo = runpy.run_path(str(common.REPO / "demos" / "demo_coulomb_friction.py"),
                          run_name="coulomb_bound_cost")
    out = Path(tempfile.mkdtemp(prefix="coulomb_cost_"))

    def timed(bound, i):
        folder = out / f"{bound}{i}"
        summary = dd.run(demo["problem"](4.0, bound=bound, n=args.n, T=args.T), folder,
                         progress=False, figures=False)
        assert summary["status"] == "completed", summary["status"]
        return median_step(folder)
    timed("coulomb", "warm"), timed("constant", "warm")
    ratios, differences = [], []
    for i in range(args.pairs):
        order = ("coulomb", "constant") if i % 2 == 0 else ("constant", "coulomb")
        t = {bound: timed(bound, i) for bound in order}
        ratios.append(t["coulomb"] / t["constant"])
        differences.append(t["coulomb"] - t["constant"])
        print(f"pair {i}: coulomb {1e3 * t['coulomb']:.3f} ms, constant "
              f"{1e3 * t['constant']:.3f} ms, ratio {ratios[-1]:.3f}", flush=True)
    print(f"n = {args.n} ({4 * args.n} x {args.n} cells), {args.pairs} pairs: median ratio "
          f"coulomb/constant {np.median(ratios):.3f}, median difference "
          f"{1e6 * np.median(differences):.0f} us per step")


if __name__ == "__main__":
    main()
