"""3-D contact: wall times of the 3-D contact examples at their defaults, and the
direct/AMG crossover of the 3.1 velocity system (benchmarks/README.md "3-D scaling").

    .venv/bin/python benchmarks/studies/contact_3d.py [--examples] [--crossover]

--examples: ``damage-dolfinx run <id>`` serially at the catalogue defaults for 2.3-ex1-3d,
3.1-ex1-3d, 3.3-ex1-3d, 3.3-ex3-3d (figures and XDMF included): wall time, steps, dofs, k/k_max,
the final contact and damage scalars.
--crossover: 3.1-ex1-3d for n = 8 ... 32 (--sizes) over 10 steps (T = 0.1, stability check off), the velocity
system (a) factorised once (MUMPS LU, the 2-D default) and (b) CG + GAMG with the rigid-body
modes (set up once): the first step (factorisation / AMG set-up) and the median later step.
Writes benchmarks/reference_output/contact_3d/{examples,crossover}.{md,json}.
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / "benchmarks" / "reference_output" / "contact_3d"
ENV = dict(os.environ, OMP_NUM_THREADS="1", MPLBACKEND="Agg")
EXAMPLES = ["2.3-ex1-3d", "3.1-ex1-3d", "3.3-ex1-3d", "3.3-ex3-3d"]
DIRECT = ["-mech_ksp_type", "preonly", "-mech_pc_type", "lu",
          "-mech_pc_factor_mat_solver_type", "mumps"]

def _amg_options() -> list:
    """scalable.MECH_AMG as command-line options (below the size threshold the code defaults
    are the direct ones, so every AMG option is given explicitly)."""
    sys.path.insert(0, str(ROOT))
    from damage_dolfinx.numerics.scalable import MECH_AMG
    return [x for key, value in MECH_AMG.items() for x in (f"-mech_{key}", str(value))]


AMG = _amg_options()


def run(args, out: Path) -> tuple[dict, list, float]:
    """(summary, history rows, wall time) of `damage-dolfinx run ARGS --out OUT` (serial)."""
    cmd = [sys.executable, "-m", "damage_dolfinx.cli", "run", *args, "--out", str(out),
           "--quiet", "--overwrite"]
    start = time.perf_counter()
    subprocess.run(cmd, env=ENV, check=True, cwd=ROOT)
    wall = time.perf_counter() - start
    summary = json.loads((out / "summary.json").read_text())
    with open(out / "history.csv") as f:
        rows = list(csv.DictReader(f))
    return summary, rows, wall


def examples(tmp: Path) -> list:
    records = []
    for ex in EXAMPLES:
        s, rows, wall = run([ex], tmp / ex)
        fin = s["final"]
        rec = {"id": ex, "command": f"damage-dolfinx run {ex} --out <dir>", "wall_s": wall,
               "run_wall_s": s["wall_time_s"], "steps": s["steps_done"], "k": s["k"],
               "T": s["t_final"], "dofs_u": s["mesh"]["dofs_u"], "cells": s["mesh"]["cells"],
               "k_over_k_max": s.get("k_over_k_max"), "k_max": s.get("k_max"),
               "zeta_min": fin["zeta_min"], "u_L2": fin["u_L2"],
               "penetration_rms": fin.get("penetration_rms"),
               "max_penetration": s.get("max_penetration"),
               "iterations": s["iterations"], "timings_s": s["timings_s"],
               "figures": [f["file"] for f in s["outputs"]["figures"]]}
        records.append(rec)
        for fig in rec["figures"]:  # kept next to the record (looked at; the XDMF is not kept)
            shutil.copy(tmp / ex / fig, OUT / f"{ex}_{fig}")
        print(json.dumps({k: rec[k] for k in ("id", "wall_s", "steps", "dofs_u", "k_over_k_max",
                                              "zeta_min")}), flush=True)
    lines = ["| example | dofs (u) | cells | steps | k | k/k_max | wall time [s] | min zeta | "
             "max / RMS penetration |", "|---|---|---|---|---|---|---|---|---|"]
    for r in records:
        pen = r["max_penetration"] if r["max_penetration"] is not None else r["penetration_rms"]
        kind = "max" if r["max_penetration"] is not None else "RMS"
        kk = f"{r['k_over_k_max']:.2f}" if r["k_over_k_max"] else "-"
        lines.append(f"| {r['id']} | {r['dofs_u']} | {r['cells']} | {r['steps']} | {r['k']:g} | "
                     f"{kk} | {r['wall_s']:.1f} | {r['zeta_min']:.4f} | {kind} {pen:.3g} |")
    return records, lines


def crossover(tmp: Path, sizes=(8, 12, 16, 24, 32)) -> list:
    records = []
    for n in sizes:
        for name, opts in (("direct", DIRECT), ("amg", AMG)):
            s, rows, wall = run(["3.1-ex1-3d", "--n", str(n), "--T", "0.1", "--no-figures",
                                 "--set", "stability_check=off", *opts], tmp / f"x{n}{name}")
            steps = [float(r["step_time_s"]) for r in rows[1:]]  # row 0 is t = 0
            rec = {"n": n, "solver": name, "dofs_u": s["mesh"]["dofs_u"], "first_step_s": steps[0],
                   "median_step_s": statistics.median(steps[1:]),
                   "velocity_s": s["timings_s"]["velocity"],
                   "mech_its_per_step": s["iterations"]["mech_ksp"] / len(steps),
                   "u_L2": s["final"]["u_L2"], "wall_s": wall}
            records.append(rec)
            print(json.dumps(rec), flush=True)
    lines = ["| n | dofs (u) | direct: first step [s] | direct: later steps [s] | "
             "AMG: first step [s] | AMG: later steps [s] | CG its/step | 100-step cost direct / "
             "AMG [s] | u_L2 rel. diff. |", "|---|---|---|---|---|---|---|---|---|"]
    for n in sizes:
        d, a = [next(r for r in records if r["n"] == n and r["solver"] == s)
                for s in ("direct", "amg")]
        cost = [r["first_step_s"] + 99 * r["median_step_s"] for r in (d, a)]
        lines.append(f"| {n} | {d['dofs_u']} | {d['first_step_s']:.3f} | {d['median_step_s']:.4f} "
                     f"| {a['first_step_s']:.3f} | {a['median_step_s']:.4f} | "
                     f"{a['mech_its_per_step']:.1f} | {cost[0]:.1f} / {cost[1]:.1f} | "
                     f"{abs(a['u_L2'] - d['u_L2']) / d['u_L2']:.1e} |")
    return records, lines


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--examples", action="store_true")
    ap.add_argument("--crossover", action="store_true")
    ap.add_argument("--sizes", type=int, nargs="+", default=[8, 12, 16, 24, 32],
                    help="n of the crossover runs")
    args = ap.parse_args()
    both = not (args.examples or args.crossover)
    OUT.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        for flag, name, fn in ((args.examples, "examples", examples),
                               (args.crossover, "crossover",
                                lambda tmp: crossover(tmp, args.sizes))):
            if flag or both:
                records, lines = fn(Path(tmp))
                (OUT / f"{name}.json").write_text(json.dumps(records, indent=1))
                (OUT / f"{name}.md").write_text("\n".join(lines) + "\n")
                print("\n".join(lines))


if __name__ == "__main__":
    main()
