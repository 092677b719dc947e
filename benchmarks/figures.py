"""Regenerate the thesis figures (PNG, named after the thesis figure numbers).

    python benchmarks/figures.py [--quick] [--np 2] [--out results/figures] [--only ID ...]

Runs every catalogue example (and its variants) with `damage-dolfinx run` under
`mpirun -n NP`, copies the figures into OUT and writes OUT/index.json (command, status and wall
time of each run). Quick mode: coarse meshes at the thesis time steps; full mode: thesis
resolutions. See damage_dolfinx/reproduce.py.
"""
import argparse
from pathlib import Path

from damage_dolfinx import reproduce

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
failed = [r for r in index["runs"] if r["returncode"] != 0]
print(f"{len(index['figures'])} figures from {len(index['runs'])} runs in {index['wall_time_s']} s "
      f"({mode} mode, {a.np} ranks) -> {out}; failed runs: {[r['example'] for r in failed] or 'none'}")
