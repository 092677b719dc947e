"""3-D scaling record of 2.1-ex1-3d (issue 17): time per step, Krylov iterations per solve and
peak memory per rank against the number of unknowns, serially and on 2 ranks, with the fitted
exponent of time per step against dofs.

    flock /tmp/team/heavy.lock .venv/bin/python benchmarks/threed_scaling.py --n 10 20 30 40 60

Each size runs 3 steps (k = 0.1, T = 0.3) through the command line; the time per step is the
median of steps 1-3 of history.csv (step 0 has no load), the peak memory is /usr/bin/time's
maximum resident set size of every rank. Writes results/threed_scaling/scaling.{csv,md,png}.
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1", OMP_NUM_THREADS="1", MPLBACKEND="Agg")


def measure(n: int, ranks: int, out: Path) -> dict:
    cmd = ["/usr/bin/time", "-f", "peak_rss_kb=%M", sys.executable, "-m", "damage_dolfinx.cli",
           "run", "2.1-ex1-3d", "--n", str(n), "--k", "0.1", "--T", "0.3", "--no-figures",
           "--quiet", "--checkpoint-seconds", "0", "--overwrite", "--out", str(out)]
    if ranks > 1:
        cmd = ["mpirun", "-n", str(ranks)] + cmd
    proc = subprocess.run(cmd, cwd=ROOT, env=ENV, capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{proc.stdout}\n{proc.stderr}")
    summary = json.loads((out / "summary.json").read_text())
    with open(out / "history.csv") as f:
        rows = [r for r in csv.DictReader(f) if int(r["step"]) > 0]
    rss = [int(v) for v in re.findall(r"peak_rss_kb=(\d+)", proc.stderr)]
    mesh = summary["mesh"]
    return {"n": n, "ranks": ranks, "dofs_u": mesh["dofs_u"], "dofs_zeta": mesh["dofs_zeta"],
            "step_s": float(np.median([float(r["step_time_s"]) for r in rows])),
            "mech_its": max(int(r["mech_its"]) for r in rows),
            "damage_its": max(int(r["damage_its"]) for r in rows),
            "peak_rss_mb_per_rank": max(rss) / 1024.0, "wall_s": summary["wall_time_s"]}


def fit_exponent(rows) -> float:
    """Slope of log(time per step) against log(dofs) over the sizes from 10^4 dofs on."""
    big = [r for r in rows if r["dofs_u"] >= 1e4]
    if len(big) < 2:
        return float("nan")
    return float(np.polyfit(np.log([r["dofs_u"] for r in big]),
                            np.log([r["step_s"] for r in big]), 1)[0])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, nargs="+", default=[10, 20, 30, 40])
    ap.add_argument("--ranks", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--out", default=str(ROOT / "results" / "threed_scaling"))
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for ranks in args.ranks:
        for n in args.n:
            row = measure(n, ranks, out / f"run_n{n}_p{ranks}")
            rows.append(row)
            print(json.dumps(row), flush=True)
    keys = list(rows[0])
    with open(out / "scaling.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)
    lines = ["| ranks | n | dofs u | time/step [s] | CG its (elasticity) | CG its (damage) | "
             "peak RSS/rank [MB] |", "|---|---|---|---|---|---|---|"]
    lines += [f"| {r['ranks']} | {r['n']} | {r['dofs_u']} | {r['step_s']:.3g} | {r['mech_its']} | "
              f"{r['damage_its']} | {r['peak_rss_mb_per_rank']:.0f} |" for r in rows]
    for ranks in args.ranks:
        lines.append(f"\nfitted exponent of time per step against dofs ({ranks} rank(s), dofs >= "
                     f"1e4): {fit_exponent([r for r in rows if r['ranks'] == ranks]):.2f}")
    (out / "scaling.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    from damage_dolfinx import figstyle
    fig, (a1, a2) = figstyle.plt().subplots(1, 2, figsize=(9, 3.6))
    for ranks in args.ranks:
        sel = [r for r in rows if r["ranks"] == ranks]
        d = [r["dofs_u"] for r in sel]
        a1.loglog(d, [r["step_s"] for r in sel], "o-",
                  label=f"{ranks} rank(s), slope {fit_exponent(sel):.2f}")
        a2.semilogx(d, [r["mech_its"] for r in sel], "o-", label=f"elasticity, {ranks} rank(s)")
        a2.semilogx(d, [r["damage_its"] for r in sel], "s--", label=f"damage, {ranks} rank(s)")
    a1.set_xlabel("displacement unknowns")
    a1.set_ylabel("wall time per step [s]")
    a1.legend()
    a2.set_xlabel("displacement unknowns")
    a2.set_ylabel("CG iterations per solve (max)")
    a2.set_ylim(bottom=0)
    a2.legend(fontsize=7)
    figstyle.save(fig, out / "scaling.png",
                  title="2.1-ex1-3d: CG + GAMG (elasticity), CG + BoomerAMG (damage)")


if __name__ == "__main__":
    main()
