"""Wall time of each figure of a run, drawn in-process on the state after a few steps (the
drawing cost depends on the mesh, not on the time reached):

    python benchmarks/performance/figure_time.py 3.1-ex1 --n 128 [--steps 2] [--repeat 3]
        [--out DIR]

Runs `damage-dolfinx run ID --n N --T steps*k` once with figures on, timing every call that
draws a figure and the first import of matplotlib, then draws each figure again ``repeat``
times on the same state (the median of these is the cost of a figure once matplotlib is
loaded). Prints one line per figure."""
import argparse
import statistics
import sys
import tempfile
import time

from damage_dolfinx import cli
from damage_dolfinx.catalogue import examples
from damage_dolfinx.runtime import records


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("example")
    ap.add_argument("--n", type=int, required=True)
    ap.add_argument("--steps", type=int, default=2)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--out", default=None, help="run folder (kept; default: a temporary one)")
    args = ap.parse_args()
    k = examples.get(args.example).k
    times, calls = {}, []
    original = records.draw_figure

    def timed(ex, fig, stepper, out, suffix=""):
        start = time.perf_counter()
        entry = original(ex, fig, stepper, out, suffix)
        times.setdefault(fig.filename, []).append(time.perf_counter() - start)
        calls.append((ex, fig, stepper, out, suffix))
        return entry
    records.draw_figure = timed
    start = time.perf_counter()
    from damage_dolfinx.viz import figstyle
    figstyle.pyplot_styled()  # matplotlib's import, apart from the drawing
    mpl_import = time.perf_counter() - start
    out = args.out or tempfile.mkdtemp()
    sys.argv = ["damage-dolfinx", "run", args.example, "--n", str(args.n),
                "--T", f"{args.steps * k:.12g}", "--quiet", "--overwrite", "--out", out]
    try:
        cli.main()
    except SystemExit as exc:
        if exc.code not in (0, None):
            raise
    first = {name: t[0] for name, t in times.items()}
    for call in list(calls):
        for _ in range(args.repeat):
            timed(*call)
    print(f"{args.example} n = {args.n}: matplotlib import {mpl_import:.3f} s")
    for name, t in times.items():
        print(f"  {name}: first {first[name]:.3f} s, then {statistics.median(t[1:]):.3f} s "
              f"(median of {len(t) - 1})")
    print(f"  all figures, first drawing: {sum(first.values()):.3f} s")


if __name__ == "__main__":
    main()
