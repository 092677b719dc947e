"""Per-step time of two checkouts of the package, A/B on one machine in one run.

    python benchmarks/performance/step_time_ab.py OLD_PYTHON NEW_PYTHON 2.1-ex1:50 3.3-ex1 \
        [--n 48] [--pairs 10] [--budget 240] [--run-seconds 8] [--json out.json]

OLD_PYTHON and NEW_PYTHON are the Python interpreters of the two checkouts (each imports its
own ``damage_dolfinx``). An example is given as ``ID`` (run at ``--n`` cells per side) or
``ID:N``. Every run is a whole ``damage-dolfinx run ID --n N --T T --no-figures --quiet``.

The measure of one run is the median of history.csv's ``step_time_s`` over its steps (the
first step, with its first factorisations, left out): a burst of load from elsewhere on the
machine moves a few steps, not the median. With ``--clock cpu`` (the default) the step timer
of both checkouts reads the process's CPU time, so a step is not charged for the time the
process waited for a core. For each example:

1. one warm-up run of each checkout with a short final time (JIT caches, the page cache;
   its default time step k and step time choose T so that a timed run steps for about
   ``--run-seconds``);
2. pairs of timed runs, the order alternating (AB, BA, AB, ...) so that a slow drift of the
   machine cancels (with ``--together 0,1``: the two of a pair at the same time, each pinned to
   its own processor, the processors swapped every pair), until ``--pairs`` pairs are done
   or ``--budget`` seconds have passed (at least 3 pairs);
3. the ratio NEW/OLD of each pair, their median, and a bootstrap 95 % interval of that
   median (pairs resampled with replacement, 10 000 times).

An interval that lies wholly above 1.05 says the new checkout is more than 5 % slower per
step; one that contains 1 says no difference was resolved. Run each example's set on an
otherwise idle machine, or at least alone among heavy jobs.
"""
import argparse
import csv
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


#: the command line, with the step clock: ``cpu`` makes the package's step timer (it reads
#: time.perf_counter around each step) read the process's CPU time instead, so that the time
#: the process waits for a core while others run is not counted
LAUNCH = {"wall": "from damage_dolfinx.cli import main; import sys; sys.exit(main())",
          "cpu": "import time; time.perf_counter = time.process_time; "
                 "from damage_dolfinx.cli import main; import sys; sys.exit(main())"}


def command(python, example, n, T, out, clock):
    cmd = [python, "-c", LAUNCH[clock], "run", example, "--n", str(n), "--no-figures",
           "--quiet", "--history-every", "1", "--checkpoint-seconds", "0", "--overwrite",
           "--out", str(out)]
    return cmd + (["--T", repr(T)] if T is not None else [])


def launch(python, example, n, T, out, clock="cpu", cpu=None):
    """A whole run started; ``cpu``: the one processor it may use (None: any)."""
    cmd = command(python, example, n, T, out, clock)
    # run from the output folder: a checkout's own tree on the path would shadow the
    # interpreter's installed package
    out.mkdir(parents=True, exist_ok=True)
    pin = (lambda: os.sched_setaffinity(0, {cpu})) if cpu is not None else None
    return subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                            cwd=out, preexec_fn=pin), cmd, out


def finish(started):
    """(median step time over steps >= 2, steps done, k) of a started run."""
    proc, cmd, out = started
    _, err = proc.communicate()
    if proc.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed ({proc.returncode}): {err.strip()[-400:]}")
    with open(out / "history.csv", newline="") as f:
        times = [float(r["step_time_s"]) for r in csv.DictReader(f) if int(r["step"]) >= 2]
    summary = json.loads((out / "summary.json").read_text())
    return (float(np.median(times)) if times else float("nan"), int(summary["steps_done"]),
            float(summary["k"]))


def run(python, example, n, T, out, clock="cpu"):
    return finish(launch(python, example, n, T, out, clock))


def bootstrap_median(ratios, resamples=10000, seed=0):
    """2.5 and 97.5 percentiles of the median of ``ratios`` resampled with replacement."""
    rng = np.random.default_rng(seed)
    r = np.asarray(ratios)
    medians = np.median(r[rng.integers(0, len(r), (resamples, len(r)))], axis=1)
    return float(np.percentile(medians, 2.5)), float(np.percentile(medians, 97.5))


def measure(old, new, example, n, args, work):
    # warm-up: the default time step k (a final time below k would shorten it: the first
    # final time that gives two steps has the default k), then 20 steps of each checkout,
    # which also tell the step time
    for probe_T in (1e-3, 1e-2, 1e-1, 1.0):
        _, probe_steps, k = run(old, example, n, probe_T, work / "probe", args.clock)
        if probe_steps >= 2:
            break
    run(new, example, n, 20 * k, work / "warm", args.clock)
    t_step, _, _ = run(old, example, n, 20 * k, work / "warm", args.clock)
    steps = int(min(max(args.run_seconds / max(t_step, 1e-6), 30), args.max_steps))
    T = steps * k
    per = {"old": [], "new": []}
    ratios = []
    start = time.perf_counter()
    while len(ratios) < args.pairs and (len(ratios) < 3
                                        or time.perf_counter() - start < args.budget):
        order = ("old", "new") if len(ratios) % 2 == 0 else ("new", "old")
        python = {"old": old, "new": new}
        got = {}
        if args.together:  # both at once, each on its own processor, swapped every pair
            runs = {which: launch(python[which], example, n, T, work / which, args.clock, cpu)
                    for which, cpu in zip(order, args.together)}
            for which in order:
                got[which], n_steps, _ = finish(runs[which])
        else:
            for which in order:
                got[which], n_steps, _ = run(python[which], example, n, T, work / which,
                                             args.clock)
        per["old"].append(got["old"])
        per["new"].append(got["new"])
        ratios.append(got["new"] / got["old"])
    lo, hi = bootstrap_median(ratios)
    return {"example": example, "n": n, "clock": args.clock, "together": bool(args.together),
            "k": k, "steps_per_run": n_steps,
            "pairs": len(ratios),
            "old_median_step_s": float(np.median(per["old"])),
            "new_median_step_s": float(np.median(per["new"])),
            "ratio_new_old_median": float(np.median(ratios)), "ratio_ci95": [lo, hi],
            "ratios": ratios, "seconds": time.perf_counter() - start}


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("old_python", help="interpreter of the reference checkout (A)")
    p.add_argument("new_python", help="interpreter of the checkout under test (B)")
    p.add_argument("examples", nargs="+", help="ID or ID:N")
    p.add_argument("--n", type=int, default=48, help="cells per side (default 48)")
    p.add_argument("--pairs", type=int, default=10, help="timed pairs per example (default 10)")
    p.add_argument("--budget", type=float, default=240.0,
                   help="seconds of timed pairs per example, at least 3 pairs (default 240)")
    p.add_argument("--run-seconds", type=float, default=8.0,
                   help="stepping time of one timed run (default 8)")
    p.add_argument("--max-steps", type=int, default=2000)
    p.add_argument("--clock", choices=("cpu", "wall"), default="cpu",
                   help="step time as the process's CPU time (default) or wall time")
    p.add_argument("--together", metavar="CPU,CPU", type=lambda s: [int(c) for c in s.split(",")],
                   help="run the two of a pair at the same time, pinned to these two "
                        "processors (swapped every pair): both see the same state of the machine")
    p.add_argument("--json", help="write the results to this JSON file")
    args = p.parse_args()
    # absolute, not resolved: a venv's interpreter is a symlink that must stay in its venv
    old, new = (os.path.abspath(shutil.which(x) or x) for x in (args.old_python, args.new_python))
    results = []
    work = Path(tempfile.mkdtemp(prefix="step-time-ab-"))
    try:
        for item in args.examples:
            example, _, n = item.partition(":")
            res = measure(old, new, example, int(n or args.n), args,
                          work)
            results.append(res)
            lo, hi = res["ratio_ci95"]
            print(f"{example:9s} n={res['n']:3d} steps/run={res['steps_per_run']:5d} "
                  f"pairs={res['pairs']:2d} old={1e3 * res['old_median_step_s']:8.3f} ms "
                  f"new={1e3 * res['new_median_step_s']:8.3f} ms "
                  f"new/old={res['ratio_new_old_median']:.3f} [{lo:.3f}, {hi:.3f}]", flush=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1) + "\n")


if __name__ == "__main__":
    main()
