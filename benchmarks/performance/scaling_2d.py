"""2-D scaling record: time per step against the number of unknowns for 2.1-ex1 (quasistatic,
elasticity + damage PDE) and 3.1-ex1 (dynamic, velocity + damage obstacle), serially and on 2
ranks, with the fitted exponent; the direct/AMG crossover from which the size threshold of the
solver choice (``damage_dolfinx/numerics/scalable.py``, ``AMG_MIN_DOFS``) was chosen; and the
difference between the two solvers' answers.

    .venv/bin/python benchmarks/performance/scaling_2d.py run 2.1-ex1 --n 160 [--ranks 2] [--mode amg]
    .venv/bin/python benchmarks/performance/scaling_2d.py report

``run`` measures one size (one ``damage-dolfinx run`` of a few steps, figures and field output
off, 3.1 with ``stability_check=off``: the eigenvalue estimate is a check, not part of the
scheme) and writes ``<out>/runs/<example>_n<n>_p<ranks>_<mode>.json``; an existing JSON is
kept unless --force. The run folder is kept (``<out>/folders/...``) for the field comparison.
Modes: ``auto`` (the package's rule), ``direct`` (every system factorised:
``-<prefix>amg_min_dofs`` above any size), ``amg`` (every system of the rule on CG + AMG:
``-<prefix>amg_min_dofs 0``).

Time per step: the mean of history.csv's ``step_time_s`` over the steps after the first (the
first sets up factorisations and AMG hierarchies; it is listed apart), the fastest beside it.
The cost of a 100-step run: step 0 (the t = 0 state) + step 1 + 99 later steps.
``report`` writes ``scaling.md`` (per example and ranks, the rule's runs, exponent fitted from
1e4 unknowns up), ``crossover.md`` (direct against AMG per size) and ``difference.md`` (u and
zeta of the two solvers, relative, at the sizes where both ran) from all JSON files present,
plus ``scaling.png``.
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from common import REPO, commit, sorted_fields  # noqa: E402

ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1", OMP_NUM_THREADS="1", MPLBACKEND="Agg")
#: example -> (time step, run arguments, PETSc prefixes whose rule the mode sets, history
#: columns of iterations -> label)
EXAMPLES = {
    "2.1-ex1": (0.01, [], ("mech_", "damage_"),
                {"mech_its": "CG its elasticity", "damage_its": "its damage"}),
    "3.1-ex1": (0.005, ["--set", "stability_check=off"], ("mech_",),
                {"mech_its": "CG its velocity", "damage_its": "Newton its damage"}),
}
MODES = ("auto", "direct", "amg")
#: a size above any mesh: ``direct`` factorises every system
NEVER = 10 ** 15
FIT_FROM_DOFS = 1e4
RUN_STEPS = 100  # the run length of the crossover's cost


def mode_options(example: str, mode: str) -> list:
    prefixes = EXAMPLES[example][2]
    if mode == "auto":
        return []
    value = str(NEVER if mode == "direct" else 0)
    return [tok for p in prefixes for tok in (f"-{p}amg_min_dofs", value)]


def measure(example: str, n: int, ranks: int, mode: str, steps: int, folder: Path) -> dict:
    k, args, _, columns = EXAMPLES[example]
    run = folder / f"{example}_n{n}_p{ranks}_{mode}"
    cmd = ["/usr/bin/time", "-f", "peak_rss_kb=%M", sys.executable, "-m", "damage_dolfinx.cli",
           "run", example, "--n", str(n), "--k", f"{k:g}", "--T", f"{k * steps:.12g}", *args,
           "--no-figures", "--quiet", "--write-every", str(10 ** 6), "--checkpoint-seconds",
           "0", "--overwrite", "--out", str(run), *mode_options(example, mode)]
    if ranks > 1:
        cmd = ["mpirun", "-n", str(ranks)] + cmd
    start = time.perf_counter()
    proc = subprocess.run(cmd, cwd=REPO, env=ENV, capture_output=True, text=True)
    process_s = time.perf_counter() - start
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{proc.stdout}\n{proc.stderr}")
    summary = json.loads((run / "summary.json").read_text())
    with open(run / "history.csv") as f:
        rows = list(csv.DictReader(f))
    times = [float(r["step_time_s"]) for r in rows]  # step 0 (t = 0 state), 1, 2, ...
    later = times[2:]
    its = {c: [int(float(r[c])) for r in rows[1:] if r.get(c) not in (None, "")]
           for c in columns}
    rss = [int(v) / 1024.0 for v in re.findall(r"peak_rss_kb=(\d+)", proc.stderr)]
    mesh = summary["mesh"]
    return {"example": example, "n": n, "ranks": ranks, "mode": mode, "k": k, "steps": steps,
            "dofs_u": mesh["dofs_u"], "dofs_zeta": mesh["dofs_zeta"],
            "command": " ".join(cmd[3:]) if ranks == 1 else " ".join(cmd),
            "step_times_s": times, "step_s": float(np.mean(later)),
            "step_min_s": float(np.min(later)), "start_s": times[0], "first_step_s": times[1],
            "run100_s": times[0] + times[1] + (RUN_STEPS - 1) * float(np.mean(later)),
            "timings_s": summary.get("timings_s", {}), "iterations": summary.get("iterations"),
            "its": its, "run_wall_s": summary["wall_time_s"], "process_s": process_s,
            "peak_rss_mb_per_rank": rss, "folder": str(run),
            "load": os.getloadavg()[0], "commit": commit(),
            "date": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}


def load(out: Path) -> list:
    return sorted((json.loads(p.read_text()) for p in (out / "runs").glob("*.json")),
                  key=lambda r: (r["example"], r["ranks"], r["mode"], r["dofs_u"]))


def fit(rows, key="step_s") -> float:
    """Exponent a of key = c dofs_u^a over the sizes from FIT_FROM_DOFS unknowns on."""
    big = [r for r in rows if r["dofs_u"] >= FIT_FROM_DOFS]
    if len(big) < 2:
        return float("nan")
    return float(np.polyfit(np.log([r["dofs_u"] for r in big]),
                            np.log([r[key] for r in big]), 1)[0])


def its_text(values) -> str:
    if not values:
        return "-"
    lo, hi = min(values), max(values)
    return f"{lo}" if lo == hi else f"{lo}-{hi}"


def _dofs(value) -> str:
    return f"{value:,}".replace(",", " ")


def scaling_table(rows, mode="auto") -> list:
    lines = []
    for example in EXAMPLES:
        columns = EXAMPLES[example][3]
        sel = [r for r in rows if r["example"] == example and r["mode"] == mode]
        if not sel:
            continue
        head = ["ranks", "n", "dofs u", "dofs total", "time/step [s] mean (fastest)",
                "first step [s]", *columns.values(), "split per step [s]", "peak RSS/rank [MB]"]
        lines += [f"**{example}** (k = {sel[0]['k']:g}, {sel[0]['steps']} steps, {mode})", "",
                  "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        for r in sel:
            split = ", ".join(f"{key} {value / r['steps']:.3g}"
                              for key, value in r["timings_s"].items() if key != "stability")
            cells = [r["ranks"], r["n"], _dofs(r["dofs_u"]), _dofs(r["dofs_u"] + r["dofs_zeta"]),
                     f"{r['step_s']:.3g} ({r['step_min_s']:.3g})", f"{r['first_step_s']:.3g}",
                     *(its_text(r["its"][c]) for c in columns), split,
                     f"{max(r['peak_rss_mb_per_rank'] or [float('nan')]):.0f}"]
            lines.append("| " + " | ".join(str(c) for c in cells) + " |")
        lines.append("")
        for ranks in sorted({r["ranks"] for r in sel}):
            part = [r for r in sel if r["ranks"] == ranks]
            span = [r["dofs_u"] for r in part if r["dofs_u"] >= FIT_FROM_DOFS]
            if span:
                lines.append(f"{example}, {ranks} rank(s): exponent of time per step against "
                             f"dofs u, {min(span):.3g} to {max(span):.3g}: **{fit(part):.2f}**  ")
        lines.append("")
    return lines


def crossover_table(rows) -> list:
    lines = []
    pairs = {}
    for r in rows:
        if r["mode"] in ("direct", "amg"):
            pairs.setdefault((r["example"], r["ranks"], r["n"]), {})[r["mode"]] = r
    head = ["example", "ranks", "n", "dofs u", "direct: first step / later [s]",
            "AMG: first step / later [s]", "later steps direct / AMG",
            f"{RUN_STEPS}-step cost direct / AMG [s]", "faster"]
    lines += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for key in sorted(pairs):
        both = pairs[key]
        if len(both) < 2:
            continue
        d, a = both["direct"], both["amg"]
        cells = [key[0], key[1], key[2], _dofs(d["dofs_u"]),
                 f"{d['first_step_s']:.3g} / {d['step_s']:.3g}",
                 f"{a['first_step_s']:.3g} / {a['step_s']:.3g}",
                 f"{d['step_s'] / a['step_s']:.2f}",
                 f"{d['run100_s']:.3g} / {a['run100_s']:.3g}",
                 "AMG" if a["run100_s"] < d["run100_s"] else "direct"]
        lines.append("| " + " | ".join(str(c) for c in cells) + " |")
    return lines


def difference(rows) -> list:
    """max-norm and L2 (nodal) relative differences of u and zeta, AMG against direct."""
    pairs = {}
    for r in rows:
        if r["mode"] in ("direct", "amg"):
            pairs.setdefault((r["example"], r["ranks"], r["n"]), {})[r["mode"]] = r
    head = ["example", "ranks", "n", "dofs u", "t", "u: rel. diff. max / l2",
            "zeta: rel. diff. max / l2"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    out = []
    for key in sorted(pairs):
        both = pairs[key]
        if len(both) < 2:
            continue
        files = [Path(both[m]["folder"]) / "fields_final.npz" for m in ("direct", "amg")]
        if not all(f.exists() for f in files):
            continue
        fd, fa = (sorted_fields(f, ["u", "zeta"]) for f in files)
        cells = [key[0], key[1], key[2], _dofs(both["direct"]["dofs_u"]),
                 f"{both['direct']['k'] * both['direct']['steps']:g}"]
        for name in ("u", "zeta"):
            x, y = fd[name][1], fa[name][1]
            dmax = np.abs(x - y).max() / np.abs(x).max()
            dl2 = np.linalg.norm(x - y) / np.linalg.norm(x)
            cells.append(f"{dmax:.1e} / {dl2:.1e}")
        lines.append("| " + " | ".join(str(c) for c in cells) + " |")
        out.append(cells)
    return lines


def plot(rows, path: Path):
    from damage_dolfinx.viz import figstyle
    fig, axes = figstyle.plt().subplots(1, len(EXAMPLES), figsize=(11, 4))
    for ax, example in zip(axes, EXAMPLES):
        for (mode, ranks), style in {("auto", 1): "o-C0", ("auto", 2): "s-C1",
                                     ("direct", 1): "^:C2", ("direct", 2): "v:C3"}.items():
            sel = [r for r in rows if r["example"] == example and r["mode"] == mode
                   and r["ranks"] == ranks]
            if not sel:
                continue
            d = [r["dofs_u"] for r in sel]
            label = {"auto": "package rule", "direct": "direct only"}[mode]
            ax.loglog(d, [r["step_s"] for r in sel], style[:-2], color=style[-2:],
                      label=f"{label}, {ranks} rank(s): slope {fit(sel):.2f}")
        sel = [r for r in rows if r["example"] == example and r["mode"] == "auto"
               and r["ranks"] == 1]
        if sel:
            ref = np.array([sel[0]["dofs_u"], sel[-1]["dofs_u"]], float)
            ax.loglog(ref, sel[0]["step_s"] * ref / ref[0], color="0.6", lw=0.8,
                      label="slope 1")
        ax.set_xlabel("displacement / velocity unknowns")
        ax.set_ylabel("time per step [s]")
        ax.set_title(example)
        ax.legend(fontsize=7)
    figstyle.save(fig, path, title="2-D time per step against unknowns")


def report(out: Path, record: Path):
    rows = load(out)
    record.mkdir(parents=True, exist_ok=True)
    stamp = f"{time.strftime('%Y-%m-%d')}, commit {commit()}"
    (record / "scaling.md").write_text("\n".join(
        [f"<!-- {stamp}; scaling_2d.py report -->", ""] + scaling_table(rows)) + "\n")
    (record / "crossover.md").write_text("\n".join(crossover_table(rows)) + "\n")
    (record / "difference.md").write_text("\n".join(difference(rows)) + "\n")
    (record / "runs.json").write_text(json.dumps(
        [{k: v for k, v in r.items() if k != "folder"} for r in rows], indent=1))
    plot(rows, record / "scaling.png")
    for name in ("scaling.md", "crossover.md", "difference.md"):
        print((record / name).read_text())


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    one = sub.add_parser("run", help="measure one size")
    one.add_argument("example", choices=list(EXAMPLES))
    one.add_argument("--n", type=int, required=True)
    one.add_argument("--ranks", type=int, default=1)
    one.add_argument("--mode", choices=MODES, default="auto")
    one.add_argument("--steps", type=int, default=6)
    one.add_argument("--force", action="store_true")
    rep = sub.add_parser("report", help="tables, fit and plot from the measured runs")
    rep.add_argument("--record", default=str(REPO / "benchmarks" / "reference_output"
                                             / "scaling_2d"))
    for p in (one, rep):
        p.add_argument("--out", default=str(REPO / "results" / "scaling_2d"))
    args = parser.parse_args(argv)
    out = Path(args.out)
    if args.command == "report":
        report(out, Path(args.record))
        return
    target = out / "runs" / f"{args.example}_n{args.n}_p{args.ranks}_{args.mode}.json"
    if target.exists() and not args.force:
        print(f"kept {target}")
        return
    row = measure(args.example, args.n, args.ranks, args.mode, args.steps, out / "folders")
    target.parent.mkdir(parents=True, exist_ok=True)
    target.write_text(json.dumps(row, indent=1))
    print(json.dumps({k: row[k] for k in ("example", "n", "ranks", "mode", "dofs_u", "step_s",
                                          "first_step_s", "run100_s", "its")}))


if __name__ == "__main__":
    main()
