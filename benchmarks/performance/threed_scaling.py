"""3-D scaling record: time per step, Krylov iterations per solve, peak memory per rank
and set-up time against the number of unknowns, serially and on 2 ranks, for one quasistatic
(2.1-ex1-3d) and one dynamic (3.1-ex1-3d) 3-D example, with the fitted exponent of time per step
against dofs and the extrapolation to a 10^8-dof cluster run.

    .venv/bin/python benchmarks/performance/threed_scaling.py quasistatic --n 10 20 30 40
    .venv/bin/python benchmarks/performance/threed_scaling.py dynamic --n 12 20 30 40
    .venv/bin/python benchmarks/performance/threed_scaling.py report     (tables, plots, extrapolation only)

Each size is one ``damage-dolfinx run`` of a few steps (quasistatic k = 0.1, 4 steps; dynamic
k = 0.01, 6 steps, ``stability_check=off``: the SLEPc eigenvalue estimate is a check, not part of
the scheme) with GNU time (``/usr/bin/time``, where installed: peak memory and CPU time)
around every rank. Time per step: of the steps after the
first (the first sets up the AMG hierarchies; it is listed apart): the fastest of them, the
median beside it; iterations per solve from
history.csv (one elasticity or velocity solve and one damage solve per step); set-up: the run's
wall time minus its steps (mesh, spaces, forms, the t = 0 state, outputs); process: the whole
command (imports and JIT included). One JSON per (size, ranks) is written as soon as it is
measured (``<out>/<kind>/n<n>_p<ranks>.json``; existing ones are kept unless --force), so a
stopped batch loses nothing; a size whose memory estimate (kB per vertex of the largest size
measured so far) exceeds --max-gb is skipped. ``report`` writes scaling[_dynamic].{md,csv,png}
and extrapolation.md from all JSON files present.
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from common import md_head, md_row, timed_run  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
#: kind -> (example, run arguments, history column -> table label, stem of the outputs)
KINDS = {
    "quasistatic": ("2.1-ex1-3d", ["--k", "0.1", "--T", "0.4"],
                    {"mech_its": "CG its elasticity", "damage_its": "CG its damage"}, "scaling"),
    "dynamic": ("3.1-ex1-3d", ["--k", "0.01", "--T", "0.06", "--set", "stability_check=off"],
                {"mech_its": "CG its velocity", "damage_its": "Newton its damage"},
                "scaling_dynamic"),
}
FIT_FROM_DOFS = 1e4


def measure(kind: str, n: int, ranks: int, folder: Path) -> dict:
    example, args, columns, _ = KINDS[kind]
    run = folder / f"run_n{n}_p{ranks}"
    done = timed_run([example, "--n", str(n), *args, "--no-figures", "--quiet",
                      "--write-every", "1000", "--checkpoint-seconds", "0", "--overwrite",
                      "--out", str(run)], run, ranks)
    cmd, summary = done["cmd"], done["summary"]
    rows = [r for r in done["rows"] if int(r["step"]) > 0]
    times = [float(r["step_time_s"]) for r in rows]
    mesh = summary["mesh"]
    its = {c: [int(r[c]) for r in rows if r.get(c) not in (None, "")] for c in columns}
    return {"kind": kind, "example": example, "n": n, "ranks": ranks,
            "dofs_u": mesh["dofs_u"], "dofs_zeta": mesh["dofs_zeta"],
            "vertices": mesh["vertices"], "cells": mesh["cells"], "command": " ".join(cmd),
            "step_times_s": times, "step_s": float(np.median(times[1:])),
            "first_step_s": times[0], "its": its,
            "setup_s": summary["wall_time_s"] - sum(times), "run_wall_s": summary["wall_time_s"],
            "process_s": done["process_s"], "process_cpu_s": done["cpu_s"],
            "peak_rss_mb_per_rank": done["rss_mb"],
            "load": os.getloadavg()[0], "date": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}


def load_rows(folder: Path) -> list:
    """The recorded sizes; time per step = the fastest step after the first (the machine is
    shared: the fastest is the least disturbed by other jobs), the median kept beside it."""
    rows = [json.loads(p.read_text()) for p in folder.glob("n*_p*.json")]
    for r in rows:
        later = r["step_times_s"][1:]
        r["step_s"], r["step_median_s"] = float(min(later)), float(np.median(later))
    return sorted(rows, key=lambda r: (r["ranks"], r["dofs_u"]))


def fit(rows, key="step_s") -> tuple:
    """(exponent, prefactor) of key = c dofs^a over the sizes from FIT_FROM_DOFS dofs on."""
    big = [r for r in rows if r["dofs_u"] >= FIT_FROM_DOFS]
    if len(big) < 2:
        return float("nan"), float("nan")
    a, logc = np.polyfit(np.log([r["dofs_u"] for r in big]), np.log([r[key] for r in big]), 1)
    return float(a), float(np.exp(logc))


def kb_per_vertex(row) -> float:
    """Peak memory of all ranks above 200 MB base per rank, per mesh vertex (nan where the
    peak memory was not measured)."""
    rss = row["peak_rss_mb_per_rank"]
    if not rss:
        return float("nan")
    return (sum(rss) - 200.0 * len(rss)) * 1024.0 / row["vertices"]


def its_text(values) -> str:
    if not values:
        return "-"
    lo, hi = min(values), max(values)
    return f"{lo}" if lo == hi else f"{lo}-{hi}"


def table(kind: str, rows) -> str:
    columns = KINDS[kind][2]
    head = (["ranks", "n", "dofs u", "dofs total", "time/step [s] fastest (median)",
             "first step [s]"]
            + list(columns.values())
            + ["peak RSS/rank [MB]", "set-up [s]", "process wall / CPU [s]"])
    lines = [*md_head(head)]
    for r in rows:
        cells = [r["ranks"], r["n"], f"{r['dofs_u']:,}".replace(",", " "),
                 f"{r['dofs_u'] + r['dofs_zeta']:,}".replace(",", " "),
                 f"{r['step_s']:.3g} ({r['step_median_s']:.3g})", f"{r['first_step_s']:.3g}"]
        cells += [its_text(r["its"][c]) for c in columns]
        cells += [f"{max(r['peak_rss_mb_per_rank'] or [float('nan')]):.0f}",
                  f"{r['setup_s']:.3g}",
                  f"{r['process_s']:.3g} / {r.get('process_cpu_s', float('nan')):.3g}"]
        lines.append(md_row(cells))
    lines.append("")
    for ranks in sorted({r["ranks"] for r in rows}):
        sel = [r for r in rows if r["ranks"] == ranks]
        a, _ = fit(sel)
        b, _ = fit(sel, "setup_s")
        lines.append(f"Fitted exponent of time per step against dofs u ({ranks} rank(s), dofs u >= "
                     f"{FIT_FROM_DOFS:.0e}): **{a:.2f}**; of the set-up: {b:.2f}.  ")
    return "\n".join(lines) + "\n"


def plot(kind: str, rows, path: Path):
    from damage_dolfinx.viz import figstyle
    example, _, columns, _ = KINDS[kind]
    fig, (a1, a2, a3) = figstyle.pyplot_styled().subplots(1, 3, figsize=(13, 3.8))
    for ranks, colour in ((1, "C0"), (2, "C1")):
        sel = [r for r in rows if r["ranks"] == ranks]
        if not sel:
            continue
        d = np.array([r["dofs_u"] for r in sel], float)
        a, c = fit(sel)
        a1.loglog(d, [r["step_s"] for r in sel], "o-", color=colour,
                  label=f"time per step, {ranks} rank(s): slope {a:.2f}")
        a1.loglog(d, [r["setup_s"] for r in sel], "s:", color=colour, mfc="none",
                  label=f"set-up, {ranks} rank(s)")
        for (col, label), marker in zip(columns.items(), ("o-", "s--")):
            a2.semilogx(d, [max(r["its"][col]) if r["its"][col] else np.nan for r in sel],
                        marker, color=colour, mfc=colour if ranks == 1 else "none",
                        ms=7 if ranks == 1 else 10, label=f"{label}, {ranks} rank(s)")
        a3.loglog(d, [max(r["peak_rss_mb_per_rank"] or [np.nan]) for r in sel], "o-",
                  color=colour,
                  label=f"{ranks} rank(s)")
    d = np.array([r["dofs_u"] for r in rows], float)
    if d.size:
        ref = np.array([d.min(), d.max()])
        a1.loglog(ref, [r["step_s"] for r in rows if r["dofs_u"] == d.min()][0] * ref / ref[0],
                  color="0.6", lw=0.8, label="slope 1 (linear)")
    a1.set_xlabel("displacement unknowns")
    a1.set_ylabel("wall time [s]")
    a1.legend(fontsize=7)
    a2.set_xlabel("displacement unknowns")
    a2.set_ylabel("iterations per solve (max over steps)")
    a2.set_ylim(bottom=0)
    a2.legend(fontsize=7)
    a3.set_xlabel("displacement unknowns")
    a3.set_ylabel("peak RSS per rank [MB]")
    a3.legend(fontsize=7)
    figstyle.save(fig, path, title=f"{example}: time per step, iterations and memory against dofs")


def extrapolation(all_rows: dict, target=1e8) -> str:
    """What a 10^8-dof run would cost, from the measured fits (see the text it writes)."""
    lines = ["| example | serial fit over [dofs u] | exponent 1 rank | 2-rank efficiency (at) | "
             "work per step at 10^8 [core-s] | kB per vertex | memory [GB] | ranks | "
             "memory/rank [GB] | time/step [s] | steps | core-h |", "|" + "---|" * 12]
    # time/step and core-h as a range: parallel efficiency 1 (the serial work, spread) to the
    # efficiency measured from 1 to 2 ranks at the largest size
    notes = []
    for kind, rows in all_rows.items():
        one = [r for r in rows if r["ranks"] == 1]
        two = {r["n"]: r for r in rows if r["ranks"] == 2}
        if len(one) < 2 or not two:
            continue
        a1, c1 = fit(one)
        top = max((r for r in one if r["n"] in two), key=lambda r: r["dofs_u"])
        efficiency = top["step_s"] / (2 * two[top["n"]]["step_s"])
        work = c1 * target ** a1  # core-seconds per step at 10^8 dofs
        kb = max(kb_per_vertex(r) for r in rows if r["dofs_u"] >= FIT_FROM_DOFS)
        mem_gb = target / 3.0 * kb * 1024 / 1e9
        ranks = int(np.ceil(target / (top["dofs_u"] / 2)))  # the measured 2-rank load per rank
        step = work / (ranks * efficiency)
        example = KINDS[kind][0]
        steps = {"2.1-ex1-3d": 50, "3.1-ex1-3d": 100}.get(example, 100)
        fitted = [r["dofs_u"] for r in one if r["dofs_u"] >= FIT_FROM_DOFS]
        lines.append(f"| {example} | {min(fitted):.2g}-{max(fitted):.3g} | {a1:.2f} | "
                     f"{efficiency:.2f} ({top['dofs_u']:.2g}) | "
                     f"{work:.3g} | {kb:.1f} | {mem_gb:.0f} | {ranks} | "
                     f"{mem_gb / ranks + 0.2:.1f} | {work / ranks:.3g}-{step:.3g} | {steps} | "
                     f"{work * steps / 3600:.3g}-{work * steps / efficiency / 3600:.3g} |")
        notes.append(example)
    text = "\n".join(lines) + "\n"
    return text + (
        "\nHow the line is drawn: work per step at 10^8 dofs = the serial fit c N^a evaluated at "
        "N = 10^8 (core-seconds; the fit's range says how far it is carried); ranks: "
        "as many as keep the dofs per rank of the largest 2-rank run (weak scaling); time per "
        "step = work / (ranks x efficiency), efficiency from 1 (the serial work spread perfectly) "
        "down to the one measured from 1 to 2 ranks at the largest size (on this shared 2-core "
        "machine other jobs lower it; on a cluster AMG coarse levels and reductions across "
        "nodes cost more: neither is measured here); memory = the measured peak "
        "per vertex above 200 MB per rank (largest over the sizes >= 10^4 dofs), plus 0.2 GB "
        "per rank; steps: the example's default run (2.1-ex1-3d k = 0.02, T = 1; 3.1-ex1-3d "
        "k = 0.01, T = 1: the stable k is set by the contact springs, not by h, per the 3-D "
        "contact record; not checked at 10^8 dofs). core-h = work x steps / "
        "efficiency / 3600 (the same range).\n")


def report(base: Path, dest: Path):
    dest.mkdir(parents=True, exist_ok=True)
    all_rows = {}
    for kind, (_, _, _, stem) in KINDS.items():
        rows = load_rows(base / kind)
        if not rows:
            continue
        all_rows[kind] = rows
        (dest / f"{stem}.md").write_text(table(kind, rows))
        keys = [k for k in rows[0] if k not in ("its", "step_times_s", "command")]
        with open(dest / f"{stem}.csv", "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=keys + ["its"], extrasaction="ignore")
            w.writeheader()
            for r in rows:
                w.writerow({**r, "peak_rss_mb_per_rank": " ".join(
                    f"{v:.0f}" for v in r["peak_rss_mb_per_rank"]), "its": json.dumps(r["its"])})
        for r in rows:  # the per-size records, commands included
            (dest / kind).mkdir(exist_ok=True)
            (dest / kind / f"n{r['n']}_p{r['ranks']}.json").write_text(json.dumps(r, indent=1))
        plot(kind, rows, dest / f"{stem}.png")
        print(table(kind, rows))
    (dest / "extrapolation.md").write_text(extrapolation(all_rows))
    print(extrapolation(all_rows))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("kind", choices=list(KINDS) + ["report"])
    ap.add_argument("--n", type=int, nargs="+", default=[])
    ap.add_argument("--ranks", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--out", default=str(ROOT / "results" / "threed_scaling"))
    ap.add_argument("--dest", default=str(ROOT / "benchmarks" / "reference_output" / "threed_scaling"))
    ap.add_argument("--max-gb", type=float, default=14.0, help="skip sizes estimated above this")
    ap.add_argument("--force", action="store_true", help="remeasure sizes already recorded")
    args = ap.parse_args()
    base = Path(args.out)
    if args.kind != "report":
        folder = base / args.kind
        folder.mkdir(parents=True, exist_ok=True)
        for n in args.n:
            for ranks in args.ranks:
                path = folder / f"n{n}_p{ranks}.json"
                if path.is_file() and not args.force:
                    continue
                rows = load_rows(folder)
                same = [r for r in rows if r["ranks"] == ranks] or rows
                if rows:  # memory estimate from the largest size measured so far
                    top = max(same, key=lambda r: r["vertices"])
                    est = (kb_per_vertex(top) * top["vertices"] * (n / top["n"]) ** 3 / 1024
                           + 200 * ranks) / 1024
                    if est > args.max_gb:
                        print(f"skip n = {n}, {ranks} rank(s): about {est:.1f} GB", flush=True)
                        continue
                row = measure(args.kind, n, ranks, folder)
                path.write_text(json.dumps(row, indent=1))
                print(json.dumps({k: row[k] for k in ("n", "ranks", "dofs_u", "step_s",
                                                      "setup_s", "peak_rss_mb_per_rank")}),
                      flush=True)
    report(base, Path(args.dest))


if __name__ == "__main__":
    main()
