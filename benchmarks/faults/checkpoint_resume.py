"""Measured resume of a long run (issue: checkpointed long runs).

    python benchmarks/faults/checkpoint_resume.py [--id 2.4-ex1] [--n 128] [--k 0.001] [--kill-at 0.5]
        [--out results/checkpoint_resume]

1. the uninterrupted run, serially;
2. the same run on 2 ranks with a checkpoint every 50 steps, killed (SIGKILL on mpirun and its
   ranks) once a checkpoint at or beyond the fraction --kill-at of the steps exists;
3. its resume from the checkpoint, serially (another number of ranks).
Prints and writes (resume.json) the wall times, the step resumed from and the relative
differences of the final fields.
"""
import argparse
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1", MPLBACKEND="Agg", OMP_NUM_THREADS="1")


def cli(args, np_=1):
    cmd = [sys.executable, "-m", "damage_dolfinx.cli", *args]
    return ["mpirun", "-n", str(np_), *cmd] if np_ > 1 else cmd


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--id", default="2.4-ex1")
    p.add_argument("--n", default="128")
    p.add_argument("--k", default="0.001")
    p.add_argument("--kill-at", type=float, default=0.5)
    p.add_argument("--out", default="results/checkpoint_resume")
    a = p.parse_args()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    base = ["run", a.id, "--n", a.n, "--k", a.k, "--no-figures", "--quiet"]
    record = {"example": a.id, "n": a.n, "k": a.k}

    start = time.perf_counter()
    subprocess.run(cli(base + ["--overwrite", "--out", str(out / "full")]), env=ENV, check=True)
    record["uninterrupted_serial_s"] = round(time.perf_counter() - start, 1)
    steps = json.loads((out / "full" / "summary.json").read_text())["num_steps"]

    start = time.perf_counter()
    proc = subprocess.Popen(cli(base + ["--checkpoint-every", "50", "--overwrite", "--out", str(out / "part")], 2),
                            env=ENV, start_new_session=True)
    meta = out / "part" / "checkpoint.json"
    while proc.poll() is None:
        if meta.is_file() and json.loads(meta.read_text())["step"] >= a.kill_at * steps:
            subprocess.run(["pkill", "-KILL", "-s", str(proc.pid)], check=False)
            break
        time.sleep(0.05)
    proc.wait()
    record["killed_after_s"] = round(time.perf_counter() - start, 1)
    record["resumed_from_step"] = json.loads(meta.read_text())["step"]
    record["num_steps"] = steps

    start = time.perf_counter()
    subprocess.run(cli(base + ["--restart", "--out", str(out / "part")]), env=ENV, check=True)
    record["resume_serial_s"] = round(time.perf_counter() - start, 1)

    full, part = np.load(out / "full" / "fields_final.npz"), np.load(out / "part" / "fields_final.npz")
    record["relative_difference"] = {
        k: float(np.linalg.norm(part[k] - full[k]) / max(np.linalg.norm(full[k]), 1e-300))
        for k in full.files if not k.endswith("_coords")}
    (out / "resume.json").write_text(json.dumps(record, indent=2) + "\n")
    print(json.dumps(record, indent=2))


if __name__ == "__main__":
    main()
