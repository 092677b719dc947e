"""Cost per time step of Section 2.3 with the O(1) memory updates versus the plain O(n) sum.

    [mpirun -n 2] .venv/bin/python benchmarks/performance/memory_cost_2_3.py [--n 64] [--k 0.001]

Runs Example 1 (running sum) and Example 3 (recursive exponential kernel), each also with
memory_mode=sum, and reports the mean step time of the first and the last tenth of each run
(from history.csv). Writes results/bench/memory_cost_2_3.json.
"""
import argparse
import csv
import json
from pathlib import Path

import numpy as np
from mpi4py import MPI

import damage_dolfinx.catalogue  # noqa: F401 (the catalogue's ids)
from damage_dolfinx.runtime import runner

parser = argparse.ArgumentParser()
parser.add_argument("--n", type=int, default=64)
parser.add_argument("--k", type=float, default=0.001)
parser.add_argument("--out", default="results/bench")
args = parser.parse_args()
comm = MPI.COMM_WORLD
rows = []
for example, fast in (("2.3-ex1", "running"), ("2.3-ex3", "recursive")):
    n = args.n if example == "2.3-ex1" else max(1, args.n // 4)
    for mode in (fast, "sum"):
        out = Path(args.out) / f"memory_{example}_{mode}"
        s = runner.run(example, out, n=n, k=args.k, overrides={"memory_mode": mode},
                       progress=False, figures=False, write_every=10**9)
        with open(out / "history.csv") as f:
            times = np.array([float(r["step_time_s"]) for r in csv.DictReader(f)][1:])
        tenth = max(1, times.size // 10)
        rows.append({"example": example, "mode": mode, "n": n, "k": args.k,
                     "steps": int(times.size), "dofs_u": s["mesh"]["dofs_u"],
                     "first_tenth_ms": 1e3 * times[:tenth].mean(),
                     "last_tenth_ms": 1e3 * times[-tenth:].mean(),
                     "wall_time_s": s["wall_time_s"], "u_L2": s["final"]["u_L2"]})
if comm.rank == 0:
    Path(args.out).mkdir(parents=True, exist_ok=True)
    Path(args.out, "memory_cost_2_3.json").write_text(json.dumps(rows, indent=2))
    print(f"{'example':8s} {'mode':9s} {'n':>4s} {'steps':>6s} {'first 10% ms/step':>18s} "
          f"{'last 10% ms/step':>17s} {'wall s':>7s}  ||u||_L2 at T")
    for r in rows:
        print(f"{r['example']:8s} {r['mode']:9s} {r['n']:4d} {r['steps']:6d} "
              f"{r['first_tenth_ms']:18.2f} {r['last_tenth_ms']:17.2f} {r['wall_time_s']:7.1f}  "
              f"{r['u_L2']:.15e}")
