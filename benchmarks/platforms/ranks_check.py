"""Every catalogue example gives the same fields on 1, 2 and 3 MPI ranks (3 oversubscribed on a
2-core machine), at small size:

    python benchmarks/platforms/ranks_check.py --out DIR [--ranks 1 2 3] [--steps 10] [--only ID ...]

Each example runs on its quick-mode mesh (reproduce._quick_options: n / 4 or 2 h, the quick time
step) for ``--steps`` time steps on each rank count; the final nodal fields (u, zeta, von Mises,
matched by coordinates) are compared with the serial run. Writes ``DIR/ranks_check.md`` and
``.json``; exit status 1 if a difference exceeds 1e-8 relative (solver tolerance) or a run fails.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from common import rel, sorted_fields  # noqa: E402

FIELDS = ("u", "zeta", "von_mises")

TOL = 1e-8


def _options(ex, steps):
    from reproduction.reproduce import _quick_options
    opts = _quick_options(ex)
    k = float(opts[opts.index("--k") + 1]) if "--k" in opts else ex.k
    if "--T" in opts:
        i = opts.index("--T")
        del opts[i:i + 2]
    return opts + ["--T", f"{steps * k:.12g}"]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--ranks", type=int, nargs="+", default=[1, 2, 3])
    ap.add_argument("--steps", type=int, default=10)
    ap.add_argument("--only", nargs="+")
    args = ap.parse_args(argv)
    from damage_dolfinx.catalogue import examples
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1", OMP_NUM_THREADS="1", MPLBACKEND="Agg")
    rows = []
    for ex in examples.catalogue().values():
        if args.only and ex.id not in args.only:
            continue
        opts = _options(ex, args.steps)
        fields, row = {}, {"id": ex.id, "options": opts, "runs": {}}
        for np_ in args.ranks:
            folder = args.out / ex.id / f"np{np_}"
            shutil.rmtree(folder, ignore_errors=True)
            cmd = [sys.executable, "-m", "damage_dolfinx.cli", "run", ex.id, *opts, "--no-figures",
                   "--quiet", "--out", str(folder)]
            if np_ > 1:
                cmd = ["mpirun", "-n", str(np_), *cmd]
            t0 = time.perf_counter()
            proc = subprocess.run(cmd, env=env, capture_output=True, text=True)
            row["runs"][np_] = {"exit": proc.returncode, "wall_time_s": round(time.perf_counter() - t0, 1)}
            if proc.returncode == 0:
                fields[np_] = sorted_fields(folder / "fields_final.npz", FIELDS)
            else:
                row["runs"][np_]["error"] = (proc.stderr or proc.stdout).strip().splitlines()[-1:]
        diffs = {}
        base = fields.get(args.ranks[0])
        for np_ in args.ranks[1:]:
            if base is None or np_ not in fields:
                continue
            worst = 0.0
            for name, (X, v) in base.items():
                Y, w = fields[np_][name]
                if X.shape != Y.shape or np.abs(X - Y).max() > 1e-8:
                    worst = float("inf")
                    break
                worst = max(worst, rel(w, v))
            diffs[np_] = worst
        row["diffs"] = diffs
        row["ok"] = all(r["exit"] == 0 for r in row["runs"].values()) and \
            len(diffs) == len(args.ranks) - 1 and all(d < TOL for d in diffs.values())
        rows.append(row)
        print(f"{ex.id:9s} " + " ".join(f"np{n}: {r['exit']} {r['wall_time_s']:5.1f}s"
                                        for n, r in row["runs"].items())
              + "  " + " ".join(f"diff(1,{n}) = {d:.1e}" for n, d in diffs.items()), flush=True)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "ranks_check.json").write_text(json.dumps(rows, indent=1))
    lines = ["| example | options | " + " | ".join(f"{n} rank(s)" for n in args.ranks)
             + " | " + " | ".join(f"max rel. diff 1 vs {n}" for n in args.ranks[1:]) + " |",
             "|---|---|" + "---|" * (2 * len(args.ranks) - 1)]
    for r in rows:
        lines.append(f"| {r['id']} | `{' '.join(r['options'])}` | "
                     + " | ".join(f"exit {v['exit']}, {v['wall_time_s']} s" for v in r["runs"].values())
                     + " | " + " | ".join(f"{r['diffs'].get(n, float('nan')):.1e}" for n in args.ranks[1:])
                     + " |")
    (args.out / "ranks_check.md").write_text("\n".join(lines) + "\n")
    print(f"{sum(r['ok'] for r in rows)}/{len(rows)} examples equal on {args.ranks} ranks to {TOL:g}")
    sys.exit(0 if all(r["ok"] for r in rows) else 1)


if __name__ == "__main__":
    main()
