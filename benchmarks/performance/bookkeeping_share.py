"""Share of a step that goes to bookkeeping (history scalars, state check, summary, history
row) rather than to the scheme's solves:

    python benchmarks/performance/bookkeeping_share.py 3.1-ex1 --n 128 [--steps 60] [--warmup 10]
        [--history-every 1]

One run in this process (no figures, fields written only at the end, no timed checkpoints).
Per step: ``whole`` = wall time between two consecutive steps handed to on_step, ``solve`` =
the step's ``step_time_s`` of history.csv (the scheme's advance); bookkeeping = whole - solve.
Prints the medians over the steps after the warm-up (the last step, which writes the fields,
left out); with --history-every N > 1 over the steps with a history row (solve) and over all
(whole)."""
import argparse
import csv
import statistics
import tempfile
import time
from pathlib import Path

from damage_dolfinx.catalogue import examples
from damage_dolfinx.runtime.runner import run


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("example")
    ap.add_argument("--n", type=int, required=True)
    ap.add_argument("--steps", type=int, default=60)
    ap.add_argument("--warmup", type=int, default=10)
    ap.add_argument("--history-every", type=int, default=1)
    args = ap.parse_args()
    k = examples.get(args.example).k
    N = args.steps + args.warmup
    stamps = {}
    out = Path(tempfile.mkdtemp())

    def on_step(step):
        stamps[step.n] = time.perf_counter()
    run(args.example, out, n=args.n, k=k, T=N * k, figures=False, progress=False,
        checkpoint_seconds=0, write_every=N, history_every=args.history_every, on_step=on_step)
    with open(out / "history.csv") as f:
        rows = {int(r["step"]): float(r["step_time_s"]) for r in csv.DictReader(f)}
    steps = [n for n in range(args.warmup + 1, N) if n in rows]
    whole = {n: stamps[n] - stamps[n - 1] for n in range(args.warmup + 1, N)}
    w = statistics.median(whole.values())
    b = w - statistics.median(rows[n] for n in steps)
    print(f"{args.example} n = {args.n}, history every {args.history_every}: "
          f"step {w * 1e3:.2f} ms, solve {statistics.median(rows[n] for n in steps) * 1e3:.2f} "
          f"ms, bookkeeping "
          f"{b * 1e3:.2f} ms ({100 * b / w:.1f} %) (median of {len(steps)} steps)")


if __name__ == "__main__":
    main()
