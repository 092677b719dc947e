"""Performance record: time per step against the number of dofs (three sizes per problem),
serially and on 2 ranks, and the 2-rank speed-up at the largest (reference) size.

    python benchmarks/performance/performance.py [--steps 10] [--only ID ...] [--out results/performance]

Each measurement is a `damage-dolfinx run ID --n N --T steps*k` (figures off); the time per step
is the mean of history.csv's step_time_s over the steps after the first (the first includes
solver set-up), so form compilation and mesh generation are excluded. Writes performance.csv,
performance.md and performance.json.
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import time
from pathlib import Path

#: example -> (three sizes n, the reference size of its convergence study)
SIZES = {"2.1-ex1": ([20, 40, 80], 160), "2.2-ex1": ([16, 32, 64], 256),
         "2.3-ex1": ([16, 32, 64], 256), "2.4-ex1": ([16, 32, 64], 256),
         "3.1-ex1": ([16, 32, 64], 256), "3.2-ex1": ([16, 32, 64], 128),
         "3.3-ex1": ([16, 32, 64], 256)}
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1", MPLBACKEND="Agg", OMP_NUM_THREADS="1")


def measure(example, n, np_, steps, out):
    from damage_dolfinx.catalogue import examples
    k = examples.get(example).k
    cmd = [sys.executable, "-m", "damage_dolfinx.cli", "run", example, "--n", str(n),
           "--T", f"{steps * k:.12g}", "--k", f"{k:.12g}", "--no-figures", "--quiet",
           "--checkpoint-seconds", "0", "--overwrite", "--out", str(out)]
    if "stability_check" in examples.get(example).params.extra:  # a set-up cost, not per step
        cmd += ["--set", "stability_check=off"]
    if np_ > 1:
        cmd = ["mpirun", "-n", str(np_), *cmd]
    start = time.perf_counter()
    proc = subprocess.run(cmd, env=ENV, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if proc.returncode != 0:
        return {"example": example, "n": n, "ranks": np_, "error": proc.stderr.strip()[-300:]}
    summary = json.loads((out / "summary.json").read_text())
    with open(out / "history.csv") as f:
        times = [float(r["step_time_s"]) for r in csv.DictReader(f) if int(r["step"]) >= 2]
    return {"example": example, "n": n, "ranks": np_, "dofs_u": summary["mesh"].get("dofs_u"),
            "steps": len(times), "time_per_step_s": sum(times) / len(times),
            "wall_time_s": round(wall, 2)}


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--steps", type=int, default=10)
    p.add_argument("--only", nargs="+")
    p.add_argument("--out", default="results/performance")
    p.add_argument("--no-reference", action="store_true", help="skip the reference-size speed-up")
    a = p.parse_args()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = _kept_rows(out / "performance.json", a.only)
    for example, (sizes, ref) in SIZES.items():
        if a.only and example not in a.only:
            continue
        for n in sizes + ([] if a.no_reference else [ref]):
            for np_ in (1, 2):
                row = measure(example, n, np_, a.steps, out / "runs" / f"{example}-n{n}-np{np_}")
                row["reference_size"] = n == ref
                rows.append(row)
                print(json.dumps(row), flush=True)
                (out / "performance.json").write_text(json.dumps(rows, indent=1))
    write_tables(rows, out)


def _kept_rows(path: Path, only) -> list:
    """With --only, the rows of the other examples from an earlier performance.json in the same
    folder are kept, so that a partial rerun updates the record instead of replacing it."""
    if not only or not path.exists():
        return []
    return [r for r in json.loads(path.read_text()) if r["example"] not in only]


def write_tables(rows: list, out: Path):
    """performance.md (serial vs 2 ranks per size) and performance.csv from the measured rows."""
    rows = sorted(rows, key=lambda r: list(SIZES).index(r["example"]))
    lines = ["| example | n | dofs (u) | serial [ms/step] | 2 ranks [ms/step] | speed-up |",
             "|---|---|---|---|---|---|"]
    for example in dict.fromkeys(r["example"] for r in rows):
        for n in dict.fromkeys(r["n"] for r in rows if r["example"] == example):
            s = next((r for r in rows if r["example"] == example and r["n"] == n and r["ranks"] == 1), {})
            q = next((r for r in rows if r["example"] == example and r["n"] == n and r["ranks"] == 2), {})
            if "time_per_step_s" in s and "time_per_step_s" in q:
                lines.append(f"| {example} | {n}{' (ref)' if s['reference_size'] else ''} | "
                             f"{s['dofs_u']} | {1e3 * s['time_per_step_s']:.1f} | "
                             f"{1e3 * q['time_per_step_s']:.1f} | "
                             f"{s['time_per_step_s'] / q['time_per_step_s']:.2f} |")
            else:
                lines.append(f"| {example} | {n} | failed: {s.get('error') or q.get('error')} | | | |")
    (out / "performance.md").write_text("\n".join(lines) + "\n")
    with open(out / "performance.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=sorted({k for r in rows for k in r}))
        w.writeheader()
        w.writerows(rows)
    print("\n".join(lines))


if __name__ == "__main__":
    main()
