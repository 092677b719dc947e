"""Share of a step that goes to bookkeeping (history scalars, state check, summary, history
row) rather than to the scheme's solves:

    python benchmarks/performance/bookkeeping_share.py 3.1-ex1 --n 128 [--steps 60] [--warmup 10]
        [--history-every 1]

One run in this process (no figures, fields written only at the end, no timed checkpoints).
Per step: ``whole`` = wall time between two consecutive steps handed to on_step, ``solve`` =
the step's ``step_time_s`` of history.csv (the scheme's advance); bookkeeping = whole - solve
of the same step. Prints the medians over the steps after the warm-up (the last step, which
writes the fields, left out): of whole, of solve, of the per-step bookkeeping, and the share
median(bookkeeping) / median(whole) (the median of the per-step differences: a step slowed
by other work on the machine moves it less than the difference of the two medians, printed
after it as "medians' difference"); with --history-every N > 1 (the steps without a row have no
solve time) the solve over the steps with a history row, the whole over all, and the
bookkeeping is the medians' difference."""
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
    s = statistics.median(rows[n] for n in steps)
    b = statistics.median(whole[n] - rows[n] for n in steps) if args.history_every == 1 \
        else w - s
    print(f"{args.example} n = {args.n}, history every {args.history_every}: "
          f"step {w * 1e3:.2f} ms, solve {s * 1e3:.2f} ms, bookkeeping {b * 1e3:.2f} ms "
          f"({100 * b / w:.1f} %) (medians of {len(steps)} steps; medians' difference "
          f"{(w - s) * 1e3:.2f} ms, {100 * (w - s) / w:.1f} %)")


if __name__ == "__main__":
    main()
