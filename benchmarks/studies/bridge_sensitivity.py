"""How robust is the collapse load of the arch ring (Section 2.1 Example 3)? Failure load against
mesh size, time step, load rate and a few modelling switches, plus the load-rate calibration.

    [mpirun -n 2] .venv/bin/python benchmarks/studies/bridge_sensitivity.py [--quick] [--calibrate]
        [--out results/bench/bridge]

Every run is catalogue example 2.1-ex3 with one thing changed (default: h = 0.05, k = 0.001,
load_rate = 4500 kN/s, lam_u_plus = lam_u_minus = 5e9, structured mesh with 'Right' diagonals),
stepped in memory without field output until collapse (or T = 0.3 s). Sweeps:

  mesh       h = 0.1, 0.07, 0.05, 0.035, 0.025 (n_r x n_theta = 7x150 ... 28x600)
  time step  k = 0.002, 0.001, 0.0005, 0.00025
  load rate  20 (0.02 kN per step: the thesis's load increment, line 1127), 1000 (the G3
             proposal), 2000, 3000, 4500 (calibrated), 6000, 10000 kN/s
  model      tension-only damage (lam_u_minus = 0); unstructured mesh h = 0.05;
             alternating diagonals; self weight only (load_rate = 0)
  damage bound  how zeta_n is kept in [zeta_star, 1] (problems/bridge_2_1.py, damage_bound):
             obstacle (default), clamp (nodal eta_*), none (the literal linear step (2.20))

``--calibrate`` bisects the load rate (steps of 250 kN/s) for a failure load of 90 kN at the
thesis mesh and time step, i.e. reproduces the calibration of the catalogue default.
Writes OUT/sensitivity.csv, OUT/sensitivity.md and OUT/sensitivity.png (rank 0).
"""
import argparse
import csv
import dataclasses
import json
import sys
import time
from pathlib import Path

from mpi4py import MPI

BASE = {"h": 0.05, "k": 0.001, "load_rate": 4500.0}
THESIS_KN = 90.0


def parse():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="fewer, coarser runs (~20 s)")
    p.add_argument("--calibrate", action="store_true", help="also bisect load_rate for 90 kN")
    p.add_argument("--out", default="results/bench/bridge")
    return p.parse_args()


def cases(quick):
    """(study, label, h, k, overrides, geometry options) of the sweeps."""
    hs = [0.1, 0.07, 0.05] if quick else [0.1, 0.07, 0.05, 0.035, 0.025]
    ks = [0.002, 0.001, 0.0005] if quick else [0.002, 0.001, 0.0005, 0.00025]
    rates = [20, 1000, 3000, 4500, 10000] if quick else [20, 1000, 2000, 3000, 4500, 6000, 10000]
    out = [("mesh", f"h = {h}", h, BASE["k"], {}, {}) for h in hs]
    out += [("time step", f"k = {k}", BASE["h"], k, {}, {}) for k in ks]
    out += [("load rate", f"{r} kN/s", BASE["h"], BASE["k"], {"load_rate": float(r)}, {})
            for r in rates]
    out += [("model", "tension-only damage", BASE["h"], BASE["k"], {"lam_u_minus": 0.0}, {}),
            ("model", "unstructured mesh", BASE["h"], BASE["k"], {}, {"structured": False}),
            ("model", "alternating diagonals", BASE["h"], BASE["k"], {},
             {"diagonal": "AlternateRight"})]
    if not quick:
        out.append(("model", "self weight only", BASE["h"], BASE["k"], {"load_rate": 0.0}, {}))
    out += [("damage bound", label, BASE["h"], BASE["k"], {"damage_bound": b}, {})
            for b, label in (("clamp", "clamp (nodal eta_*)"), ("none", "none (literal (2.20))"))]
    return out


def collapse(h, k, overrides, geometry, comm, T=0.3):
    """Step example 2.1-ex3 (in memory) until collapse; returns a result row."""
    from damage_dolfinx.catalogue import examples
    from damage_dolfinx.geometries.bridge import arch_bridge
    ex = examples.get("2.1-ex3")
    if geometry:
        ex = dataclasses.replace(ex, mesh=lambda c, n, hh: arch_bridge(c, h=hh, **geometry))
    overrides = {"load_rate": BASE["load_rate"], **overrides}
    start = time.perf_counter()
    stepper = ex.build(comm, h=h, k=k, T=T, overrides=overrides)
    stepper.initialize()
    stepper.scalars()
    while stepper.n < stepper.num_steps:
        stepper.advance()
        stepper.scalars()
        if stepper.stop_reason():
            break
    extra = stepper.summary_extra()
    return {"h": h, "k": k, "load_rate": overrides["load_rate"],
            "cells": stepper.mesh_info()["cells"], "status": stepper.stop_reason() or "no collapse",
            "failure_load_kN": extra["failure_load_kN"], "increment_kN": extra["load_increment_kN"],
            "failure_time_s": extra["failure_time"], "failure_step": extra["failure_step"],
            "failed_at_deg": None if not extra["failed_sections"] else
            round(sum(s["angle_deg"] for s in extra["failed_sections"]) / len(extra["failed_sections"]), 1),
            "n_hinges": extra["n_hinges"], "n_mechanism_hinges": extra["n_mechanism_hinges"],
            "zeta_min": extra["zeta_min_run"],
            # hinges that barely rotate in the collapse step (not in the mechanism) in brackets
            "hinges_deg": " ".join(f"{x['angle_deg']:.0f}" if x["mechanism"] else
                                   f"({x['angle_deg']:.0f})" for x in extra["hinges"]),
            "wall_s": round(time.perf_counter() - start, 2)}


def calibrate(comm, lo=1000.0, hi=10000.0, step=250.0):
    """Smallest load rate (multiple of ``step``) whose failure load is >= 90 kN (bisection; the
    failure load grows with the rate)."""
    log = []
    while hi - lo > step:
        mid = step * round((lo + hi) / 2 / step)
        row = collapse(BASE["h"], BASE["k"], {"load_rate": mid}, {}, comm)
        log.append((mid, row["failure_load_kN"]))
        if row["failure_load_kN"] is not None and row["failure_load_kN"] >= THESIS_KN:
            hi = mid
        else:
            lo = mid
    return hi, log


def write_tables(rows, out: Path):
    keys = ["study", "case", "h", "k", "load_rate", "cells", "status", "failure_load_kN",
            "increment_kN", "failure_step", "failure_time_s", "failed_at_deg", "zeta_min", "n_hinges",
            "n_mechanism_hinges", "hinges_deg", "wall_s"]
    with open(out / "sensitivity.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)
    lines = ["| study | case | cells | failure load [kN] | increment [kN] | step | failed at [deg] "
             "| min zeta | hinges (deg from left springing; (x): not in the mechanism) | mechanism "
             "hinges | wall [s] |", "|" + "---|" * 11]
    for r in rows:
        F = "no collapse" if r["failure_load_kN"] is None else f"{r['failure_load_kN']:.4g}"
        lines.append(f"| {r['study']} | {r['case']} | {r['cells']} | {F} | {r['increment_kN']:.3g} "
                     f"| {r['failure_step']} | {r['failed_at_deg']} | {r['zeta_min']:.4g} "
                     f"| {r['n_hinges']}: "
                     f"{r['hinges_deg']} | {r['n_mechanism_hinges']} | {r['wall_s']} |")
    text = "\n".join(lines) + "\n"
    (out / "sensitivity.md").write_text(text)
    return text


def plot(rows, path):
    from damage_dolfinx.viz import figstyle
    fig, axes = figstyle.pyplot_styled().subplots(1, 3, figsize=(13, 3.8))
    for ax, (study, key, label) in zip(axes, (("mesh", "h", "mesh size $h$ [m]"),
                                              ("time step", "k", "time step $k$ [s]"),
                                              ("load rate", "load_rate", "load rate [kN/s]"))):
        sel = [r for r in rows if r["study"] == study and r["failure_load_kN"] is not None]
        x = [r[key] for r in sel]
        y = [r["failure_load_kN"] for r in sel]
        # collapse is detected at step n: the crossing lies in (P_n - increment, P_n]
        ax.errorbar(x, y, yerr=[[r["increment_kN"] for r in sel], [0.0] * len(sel)], fmt="o-",
                    capsize=3, label="failure load (bar: one load increment)")
        ax.axhline(90.0, ls="--", color="0.4", lw=1, label="thesis damage 90 kN")
        ax.axhline(87.14, ls=":", color="0.4", lw=1, label="thesis contact 87.14 kN")
        if study != "load rate":
            ax.set_xscale("log")
            ax.minorticks_off()
            ax.set_xticks(x)
            ax.set_xticklabels([f"{v:g}" for v in x], fontsize=8)
        ax.set_xlabel(label)
        ax.set_ylabel("failure load [kN]")
        ax.set_title(f"vs {study}")
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize=7)
    figstyle.save(fig, path, title="Example 2.1-3: failure load against mesh, time step and "
                  "load rate")


def main():
    args = parse()
    comm = MPI.COMM_WORLD
    out = Path(args.out)
    if comm.rank == 0:
        out.mkdir(parents=True, exist_ok=True)
    rows = []
    total = time.perf_counter()
    for study, label, h, k, overrides, geometry in cases(args.quick):
        row = {"study": study, "case": label, **collapse(h, k, overrides, geometry, comm)}
        rows.append(row)
        if comm.rank == 0:
            print(f"[{study:9s}] {label:24s} F = {row['failure_load_kN']} kN (step "
                  f"{row['failure_step']}, {row['cells']} cells, {row['wall_s']} s)", flush=True)
    calibration = None
    if args.calibrate:
        rate, log = calibrate(comm)
        calibration = {"load_rate_kN_per_s": rate, "target_kN": THESIS_KN, "bisection": log}
        if comm.rank == 0:
            print(f"calibration: load_rate = {rate:g} kN/s gives >= 90 kN; bisection {log}")
    if comm.rank == 0:
        table = write_tables(rows, out)
        plot(rows, out / "sensitivity.png")
        meta = {"base": BASE, "mpi_size": comm.size, "wall_time_s": time.perf_counter() - total,
                "rows": rows, "calibration": calibration}
        (out / "sensitivity.json").write_text(json.dumps(meta, indent=2) + "\n")
        print("\n" + table)
        print(f"{len(rows)} runs on {comm.size} rank(s) in {meta['wall_time_s']:.0f} s; "
              f"outputs in {out}/sensitivity.*")
    return 0


if __name__ == "__main__":
    sys.exit(main())
