"""Check a one-command reproduction (``make convergence`` + ``make figures``) against the committed
results: every error of every convergence study against
``reference_output/convergence/<study>/summary.json``, and the wrench of Section 3.3 Example 3
(the figures run ``runs/3.3-ex3``) against ``reference_output/wrench_3_3/wrench.json``.

    python benchmarks/reproduction/reproduction_check.py --results results [--out DIR] [--tol 1e-6]

Writes ``reproduction_check.json`` and ``.md`` into OUT (default: the results folder) with the
wall times of both commands (their index.json), the largest relative difference per study
(all cells, all error columns) and per wrench quantity; exit status 1 if one exceeds --tol.
"""
import argparse
import json
from pathlib import Path

import sys

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # benchmarks/: common.py
from common import RECORDS as REFERENCE  # noqa: E402

p = argparse.ArgumentParser()
p.add_argument("--results", default="results", help="OUT of make convergence / make figures")
p.add_argument("--out", help="where the check is written (default: --results)")
p.add_argument("--tol", type=float, default=1e-6, help="largest relative difference allowed")
a = p.parse_args()
results = Path(a.results)
out = Path(a.out or results)


def rel(x, y):
    return abs(x - y) / max(abs(y), 1e-300)


def error_columns(row):
    return [key for key in row if key.startswith("error")]


studies = []
conv_index = json.loads((results / "convergence" / "index.json").read_text())
for s in conv_index["studies"]:
    name = s["example"] + (f"-{s['variant']}" if s["variant"] else "")
    mine = json.loads((results / "convergence" / name / "summary.json").read_text())
    ref = json.loads((REFERENCE / "convergence" / name / "summary.json").read_text())
    worst, where = 0.0, None
    for r_new, r_ref in zip(mine["errors"], ref["errors"]):
        assert (r_new["n"], r_new["k"]) == (r_ref["n"], r_ref["k"]), name
        for key in error_columns(r_ref):
            d = rel(r_new[key], r_ref[key])
            if d > worst:
                worst, where = d, [r_new["n"], r_new["k"], key, r_ref[key],
                                   abs(r_new[key] - r_ref[key])]
    studies.append({"study": name, "cells": len(ref["errors"]), "wall_time_s": s["wall_time_s"],
                    "committed_wall_time_s": None, "reference_wall_time_s":
                    mine["reference"]["wall_time_s"], "reference_ranks":
                    mine["reference"].get("ranks"), "max_relative_difference": worst,
                    "at": where})
committed = {s["example"] + (f"-{s['variant']}" if s["variant"] else ""): s["wall_time_s"]
             for s in json.loads((REFERENCE / "convergence" / "index.json").read_text())["studies"]}
for s in studies:
    s["committed_wall_time_s"] = committed.get(s["study"])

wrench = {}
run = results / "figures" / "runs" / "3.3-ex3"
if (run / "summary.json").exists():
    summary = json.loads((run / "summary.json").read_text())
    final = np.load(run / "fields_final.npz")
    ref = json.loads((REFERENCE / "wrench_3_3" / "wrench.json").read_text())
    mine = {"max_penetration": summary["max_penetration"],
            "max_penetration_t": summary["max_penetration_t"],
            "penetration_at_T": summary["final"]["penetration_max"],
            "zeta_min_at_T": summary["final"]["zeta_min"],
            "von_mises_max_at_T": float(np.max(final["von_mises"]))}
    wrench = {"wall_time_s": summary["wall_time_s"], "steps": summary["steps_done"],
              "mpi_size": summary["mpi_size"],
              "quantities": {key: {"reference": ref[key], "this_run": value,
                                   "relative_difference": rel(value, ref[key])}
                             for key, value in mine.items()},
              "same_places": {
                  "max_penetration_at": summary["max_penetration_at"] == ref["max_penetration_at"],
                  "von_mises_argmax_at_T": final["von_mises_coords"][
                      int(np.argmax(final["von_mises"]))].tolist() == ref["von_mises_argmax_at_T"],
                  "zeta_argmin_at_T": final["zeta_coords"][int(np.argmin(final["zeta"]))].tolist()
                  == ref["zeta_argmin_at_T"]}}

fig_index_path = results / "figures" / "index.json"
fig_index = json.loads(fig_index_path.read_text()) if fig_index_path.exists() else {}
record = {"convergence_wall_time_s": conv_index.get("wall_time_this_invocation_s",
                                                  conv_index["wall_time_s"]),
          # elapsed: the runs of make figures overlap (two lanes, reproduce.run_figures)
          "figures_wall_time_s": fig_index.get("wall_time_this_invocation_s",
                                               fig_index.get("wall_time_s")),
          "figures_runs_wall_time_s": fig_index.get("wall_time_s"),
          "figures": len(fig_index.get("figures", [])), "figure_runs": len(fig_index.get("runs", [])),
          "failed_runs": [r.get("command") for r in fig_index.get("runs", [])
                          if r.get("returncode", 0) != 0],
          "tolerance": a.tol, "studies": studies, "wrench": wrench}
worst = max([s["max_relative_difference"] for s in studies] +
            [q["relative_difference"] for q in wrench.get("quantities", {}).values()])
record["max_relative_difference"] = worst
record["passed"] = bool(worst <= a.tol and all(wrench.get("same_places", {}).values())
                        and not record["failed_runs"])

lines = ["| study | cells | wall time (s), this run | committed | reference (s, ranks) | "
         "largest relative error difference (cell, column: error, absolute difference) |",
         "|---|---|---|---|---|---|"]
for s in studies:
    n, k, key, value, diff = s["at"] or (None, None, None, 0.0, 0.0)
    lines.append(f"| {s['study']} | {s['cells']} | {s['wall_time_s']:.0f} | "
                 f"{s['committed_wall_time_s']:.0f} | {s['reference_wall_time_s']:.0f}, "
                 f"{s['reference_ranks']} | {s['max_relative_difference']:.1e} ({n}, {k:g}, "
                 f"{key}: {value:.3e}, {diff:.1e}) |")
total = record["convergence_wall_time_s"] + (record["figures_wall_time_s"] or 0.0)
lines += ["", f"make convergence: {record['convergence_wall_time_s']:.0f} s; make figures: "
          f"{record['figures_wall_time_s']:.0f} s ({record['figures']} figures from "
          f"{record['figure_runs']} runs, failed: {len(record['failed_runs'])}); together "
          f"{total:.0f} s = {total / 60:.1f} min"]
if wrench:
    lines += ["", f"Wrench (3.3-ex3, {wrench['steps']} steps, {wrench['mpi_size']} rank): "
              f"{wrench['wall_time_s']:.0f} s"]
    for key, q in wrench["quantities"].items():
        lines.append(f"* {key}: {q['this_run']:.9g} against {q['reference']:.9g} "
                     f"({q['relative_difference']:.1e})")
    lines.append(f"* same places: {wrench['same_places']}")
lines += ["", f"largest relative difference {worst:.1e} (tolerance {a.tol:g}): "
          f"{'passed' if record['passed'] else 'FAILED'}"]
out.mkdir(parents=True, exist_ok=True)
(out / "reproduction_check.json").write_text(json.dumps(record, indent=1))
(out / "reproduction_check.md").write_text("\n".join(lines) + "\n")
print("\n".join(lines))
raise SystemExit(0 if record["passed"] else 1)
