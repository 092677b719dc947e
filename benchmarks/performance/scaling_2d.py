"""2-D scaling record: time per step against the number of unknowns for 2.1-ex1 (quasistatic,
elasticity + damage PDE) and 3.1-ex1 (dynamic, velocity + damage obstacle), serially and on 2
ranks, with the fitted exponent; the direct/AMG crossover from which the size threshold of the
solver choice (``damage_dolfinx/numerics/scalable.py``, ``AMG_MIN_DOFS``) was chosen; and the
difference between the two solvers' answers.

    .venv/bin/python benchmarks/performance/scaling_2d.py run 2.1-ex1 --n 160 [--ranks 2] [--mode amg]
        [--tag rebuild --options '-mech_amg_rebuild_its 0']
    .venv/bin/python benchmarks/performance/scaling_2d.py report

``run`` measures one size (one ``damage-dolfinx run`` of a few steps, figures and field output
off, 3.1 with ``stability_check=off``: the eigenvalue estimate is a check, not part of the
scheme) and writes ``<out>/runs/<example>_n<n>_p<ranks>_<mode>.json``; an existing JSON is
kept unless --force. The run folder is kept (``<out>/folders/...``) for the field comparison.
Modes: ``auto`` (the package's rule), ``direct`` (every system factorised:
``-<prefix>amg_min_dofs`` above any size), ``amg`` (every system of the rule on CG + AMG:
``-<prefix>amg_min_dofs 0``).

Time per step: the median of history.csv's ``step_time_s`` over the timed steps (from
FIRST_TIMED on: 2.1-ex1 steps 2-10; 3.1-ex1 steps 21-32, after its start-up transient, pressed
into the obstacle and damaging in every one; step 0, the t = 0 state, factorises; step 1 sets
up AMG hierarchies; both are listed apart, beside the whole process's wall time, which carries
the mesh and form set-up), the mean (which carries the occasional re-factorisation of 2.1's
lagged elasticity solver) and the range beside it.
The cost of a 100-step run: step 0 (the t = 0 state) + step 1 + 99 later steps.
``report`` writes ``scaling.md`` (per example and ranks, the rule's runs; the exponent of the
time per step against the unknowns, least squares on log-log from 1e4 to 1.2e6 unknowns, and the
local slopes between neighbouring sizes), ``efficiency.md`` (serial against 2 ranks per size:
speed-up and parallel efficiency), ``crossover.md`` (direct against AMG per size),
``difference.md`` (u and zeta of the two solvers, relative, at the sizes where both ran) and
``variants.md`` (each run with ``--tag NAME --options '...'``, a solver option set, against the
untagged run of the same size: time per step, iterations, the answers' difference) from all JSON
files present, plus ``scaling.png``; and it rewrites the block between the scaling markers of
benchmarks/README.md (the commands and the exponents, copied from the records, and where the
serial / 2-rank table is; ``--readme ''`` leaves it alone).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from common import REPO, commit, md_head, md_row, sorted_fields, timed_run  # noqa: E402

#: example -> (time step, run arguments, PETSc prefixes whose rule the mode sets, history
#: columns of iterations -> label)
EXAMPLES = {
    "2.1-ex1": (0.01, [], ("mech_", "damage_"),
                {"mech_its": "CG its elasticity", "damage_its": "its damage"}),
    "3.1-ex1": (0.005, ["--set", "stability_check=off"], ("mech_",),
                {"mech_its": "CG its velocity", "damage_its": "Newton its damage"}),
}
#: example -> the first timed step (history.csv's step; step 0 is the t = 0 state, step 1 sets
#: up). 3.1-ex1: steps 1-20 (t <= 0.1) are a transient whose cost per step changes (the first
#: steps before damage starts are cheaper, those where it starts dearer); from step 21
#: (t = 0.105) on, the body is pressed into the obstacle (RMS penetration >= 1e-4, rising) and
#: the damage grows in every step, so every timed step does the same work.
FIRST_TIMED = {"2.1-ex1": 2, "3.1-ex1": 21}
#: example -> the default number of steps of a run: 9 and 12 timed steps
DEFAULT_STEPS = {"2.1-ex1": 10, "3.1-ex1": 32}
MODES = ("auto", "direct", "amg")
#: a size above any mesh: ``direct`` factorises every system
NEVER = 10 ** 15
FIT_FROM_DOFS = 1e4
#: the largest size of the fit (the goal is stated from 1e4 to 1e6 unknowns)
FIT_TO_DOFS = 1.2e6
RUN_STEPS = 100  # the run length of the crossover's cost


def mode_options(example: str, mode: str) -> list:
    prefixes = EXAMPLES[example][2]
    if mode == "auto":
        return []
    value = str(NEVER if mode == "direct" else 0)
    return [tok for p in prefixes for tok in (f"-{p}amg_min_dofs", value)]


def run_name(example: str, n: int, ranks: int, mode: str, tag: str = "") -> str:
    """``<example>_n<n>_p<ranks>_<mode>[_<tag>]``: the name of a run's JSON and folder."""
    return f"{example}_n{n}_p{ranks}_{mode}" + (f"_{tag}" if tag else "")


def measure(example: str, n: int, ranks: int, mode: str, steps: int, folder: Path,
            options=(), tag: str = "") -> dict:
    k, args, _, columns = EXAMPLES[example]
    run = folder / run_name(example, n, ranks, mode, tag)
    done = timed_run([example, "--n", str(n), "--k", f"{k:g}", "--T", f"{k * steps:.12g}", *args,
                      "--no-figures", "--quiet", "--write-every", str(10 ** 6),
                      "--checkpoint-seconds", "0", "--overwrite", "--out", str(run),
                      *mode_options(example, mode), *options], run, ranks)
    cmd, summary, rows = done["cmd"], done["summary"], done["rows"]
    times = [float(r["step_time_s"]) for r in rows]  # step 0 (t = 0 state), 1, 2, ...
    first = FIRST_TIMED[example]
    later = times[first:]
    its = {c: [int(float(r[c])) for r in rows[1:] if r.get(c) not in (None, "")]
           for c in columns}
    mesh = summary["mesh"]
    return {"example": example, "n": n, "ranks": ranks, "mode": mode, "tag": tag,
            "options": list(options), "k": k, "steps": steps,
            "dofs_u": mesh["dofs_u"], "dofs_zeta": mesh["dofs_zeta"],
            "command": (f"mpirun -n {ranks} " if ranks > 1 else "") + " ".join(
                cmd[cmd.index(sys.executable):]),
            "step_times_s": times, "first_timed": first, "step_s": float(np.mean(later)),
            "step_median_s": float(np.median(later)),
            "step_min_s": float(np.min(later)), "start_s": times[0], "first_step_s": times[1],
            "run100_s": times[0] + times[1] + (RUN_STEPS - 1) * float(np.mean(later)),
            "timings_s": summary.get("timings_s", {}), "iterations": summary.get("iterations"),
            "its": its, "run_wall_s": summary["wall_time_s"], "process_s": done["process_s"],
            "peak_rss_mb_per_rank": done["rss_mb"], "folder": str(run),
            "load": os.getloadavg()[0], "commit": commit(),
            "date": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}


def load(out: Path) -> list:
    rows = [json.loads(p.read_text()) for p in (out / "runs").glob("*.json")]
    for r in rows:  # the per-step median and tag (records written before they were stored)
        r.setdefault("first_timed", 2)
        r.setdefault("step_median_s", float(np.median(timed(r))))
        r.setdefault("tag", "")
    return sorted(rows, key=lambda r: (r["example"], r["ranks"], r["mode"], r["dofs_u"]))


def timed(r) -> list:
    """The timed steps' times of run r (from its first timed step on)."""
    return r["step_times_s"][r["first_timed"]:]


def in_fit(rows) -> list:
    """The rows inside the fitted range, FIT_FROM_DOFS to FIT_TO_DOFS unknowns."""
    return [r for r in rows if FIT_FROM_DOFS <= r["dofs_u"] <= FIT_TO_DOFS]


def fit(rows, key="step_median_s") -> float:
    """Exponent a of key = c dofs_u^a, least squares on log-log over the sizes of in_fit."""
    big = in_fit(rows)
    if len(big) < 2:
        return float("nan")
    return float(np.polyfit(np.log([r["dofs_u"] for r in big]),
                            np.log([r[key] for r in big]), 1)[0])


def local_slopes(rows, key="step_median_s") -> list:
    """log(t2 / t1) / log(N2 / N1) between neighbouring sizes of in_fit, in order of size."""
    big = sorted(in_fit(rows), key=lambda r: r["dofs_u"])
    return [float(np.log(b[key] / a[key]) / np.log(b["dofs_u"] / a["dofs_u"]))
            for a, b in zip(big, big[1:])]


def its_text(values) -> str:
    if not values:
        return "-"
    lo, hi = min(values), max(values)
    return f"{lo}" if lo == hi else f"{lo}-{hi}"


def _dofs(value) -> str:
    return f"{value:,}".replace(",", " ")


def _factorisations(r) -> str:
    its = r.get("iterations") or {}
    value = its.get("mech_factorizations")
    return "-" if value is None else str(value)


def scaling_table(rows, mode="auto") -> list:
    """Per example: one row per ranks and size (the rule's runs), then the exponents."""
    lines = []
    for example in EXAMPLES:
        columns = EXAMPLES[example][3]
        sel = [r for r in rows if r["example"] == example and r["mode"] == mode]
        if not sel:
            continue
        head = ["ranks", "n", "dofs u", "dofs total", "time/step [s] median (min-max)",
                "mean [s]", "step 0 (factorises) / step 1 [s]", "factorisations",
                *columns.values(), "peak RSS/rank [MB]", "process [s]"]
        lines += [f"**{example}** (k = {sel[0]['k']:g}, {sel[0]['steps']} steps, {mode})", "",
                  *md_head(head)]
        for r in sel:
            later = timed(r)
            cells = [r["ranks"], r["n"], _dofs(r["dofs_u"]), _dofs(r["dofs_u"] + r["dofs_zeta"]),
                     f"{r['step_median_s']:.3g} ({min(later):.3g}-{max(later):.3g})",
                     f"{r['step_s']:.3g}", f"{r['start_s']:.3g} / {r['first_step_s']:.3g}",
                     _factorisations(r), *(its_text(r["its"][c]) for c in columns),
                     f"{max(r['peak_rss_mb_per_rank'] or [float('nan')]):.0f}",
                     f"{r['process_s']:.0f}"]
            lines.append(md_row(cells))
        lines.append("")
    return lines + exponent_table(rows, mode)


def exponent_table(rows, mode="auto") -> list:
    """Exponent of the time per step against the unknowns u, per example and ranks: least
    squares on log-log over FIT_FROM_DOFS..FIT_TO_DOFS (of the median and of the mean), and the
    local slopes of the median between neighbouring sizes."""
    head = ["example", "ranks", "sizes", "dofs u", "exponent (median)", "exponent (mean)",
            "local slopes (median), small to large"]
    lines = [*md_head(head)]
    for example in EXAMPLES:
        sel = [r for r in rows if r["example"] == example and r["mode"] == mode]
        for ranks in sorted({r["ranks"] for r in sel}):
            part = [r for r in sel if r["ranks"] == ranks]
            span = [r["dofs_u"] for r in in_fit(part)]
            if len(span) < 2:
                continue
            slopes = ", ".join(f"{s:.2f}" for s in local_slopes(part))
            cells = [example, ranks, len(span), f"{min(span):.3g} - {max(span):.3g}",
                     f"**{fit(part):.2f}**", f"{fit(part, 'step_s'):.2f}", slopes]
            lines.append(md_row(cells))
    return lines + [""]


def efficiency_table(rows, mode="auto") -> list:
    """Per example and size: the time per step serially and on 2 ranks (median, min-max of the
    timed steps), the speed-up (serial / 2 ranks) and the parallel efficiency (speed-up / 2)."""
    head = ["example", "n", "dofs u", "serial: time/step [s] median (min-max)",
            "2 ranks: time/step [s] median (min-max)", "speed-up 1 -> 2 ranks",
            "parallel efficiency", "step 0 + step 1 [s] serial / 2 ranks"]
    lines = [*md_head(head)]

    def cell(r):
        if r is None:
            return "-"
        t = timed(r)
        return f"{r['step_median_s']:.3g} ({min(t):.3g}-{max(t):.3g})"

    for example in EXAMPLES:
        sel = [r for r in rows if r["example"] == example and r["mode"] == mode]
        by = {(r["n"], r["ranks"]): r for r in sel}
        for n in sorted({r["n"] for r in sel}):
            one, two = by.get((n, 1)), by.get((n, 2))
            ref = one or two
            speed = one["step_median_s"] / two["step_median_s"] if one and two else None
            setup = " / ".join("-" if r is None else f"{r['start_s'] + r['first_step_s']:.3g}"
                               for r in (one, two))
            cells = [example, n, _dofs(ref["dofs_u"]), cell(one), cell(two),
                     "-" if speed is None else f"{speed:.2f}",
                     "-" if speed is None else f"{speed / 2:.2f}", setup]
            lines.append(md_row(cells))
    return lines + [""]


def commands(rows, mode="auto") -> list:
    """The script's commands that measured the rule's runs: one loop per example and ranks."""
    lines = []
    for example in EXAMPLES:
        for ranks in (1, 2, 3, 4):
            sel = [r for r in rows if r["example"] == example and r["mode"] == mode
                   and r["ranks"] == ranks]
            if not sel:
                continue
            steps = sorted({r["steps"] for r in sel})
            sizes = " ".join(str(r["n"]) for r in sorted(sel, key=lambda r: r["n"]))
            extra = (f" --ranks {ranks}" if ranks > 1 else "") + (
                f" --steps {steps[0]}" if len(steps) == 1
                and steps[0] != DEFAULT_STEPS[example] else "")
            lines.append(f"    for n in {sizes}; do .venv/bin/python "
                         f"benchmarks/performance/scaling_2d.py run {example} --n $n{extra}; done")
    return lines + ["    .venv/bin/python benchmarks/performance/scaling_2d.py report"]


#: the lines of benchmarks/README.md between which ``report`` writes its block
README_BEGIN = "<!-- scaling_2d.py report: begin (written by the report step) -->"
README_END = "<!-- scaling_2d.py report: end -->"


def readme_block(rows, record_name: str) -> list:
    """The block ``report`` writes into the README: the commands and the exponents (marked
    with the record they are copied from), and where the serial / 2-rank table is."""
    return (["**Commands** (each size is a separate process, one at a time on the machine; "
             "`runs.json` has each run's own command line):", ""] + commands(rows) + [
             "", f"**Exponents** (`{record_name}/scaling.md`, with every run's full row):", "",
             f"<!-- record: {record_name}/scaling.md -->"] + exponent_table(rows) + [
             f"Time per step serially and on 2 ranks at every size, the speed-up and the first "
             f"two steps: `{record_name}/efficiency.md`."])


def write_readme(readme: Path, block: list) -> bool:
    """Replace the lines between README_BEGIN and README_END of ``readme`` by ``block``;
    False (and the file untouched) when the markers are missing."""
    if not readme.is_file():
        return False
    lines = readme.read_text().splitlines()
    if README_BEGIN not in lines or README_END not in lines:
        return False
    i, j = lines.index(README_BEGIN), lines.index(README_END)
    readme.write_text("\n".join(lines[:i + 1] + block + lines[j:]) + "\n")
    return True


def solver_pairs(rows) -> dict:
    """(example, ranks, n) -> {"direct": row, "amg": row}: the ``direct`` run, else the rule's
    (``auto``) run where the rule factorises (below AMG_MIN_DOFS[2] unknowns), and the ``amg``
    run, both of the same number of steps (a pair of different lengths is left out)."""
    from damage_dolfinx.numerics.scalable import AMG_MIN_DOFS
    pairs = {}
    for r in sorted(rows, key=lambda r: r["mode"] == "direct"):  # direct wins over auto
        role = "direct" if r["mode"] == "auto" and r["dofs_u"] < AMG_MIN_DOFS[2] else r["mode"]
        if role in ("direct", "amg"):
            pairs.setdefault((r["example"], r["ranks"], r["n"]), {})[role] = r
    # only runs of the same length compare (the same final time, the same timed steps)
    return {key: both for key, both in pairs.items()
            if len({r["steps"] for r in both.values()}) == 1}


def crossover_table(rows) -> list:
    lines = []
    pairs = solver_pairs(rows)
    head = ["example", "ranks", "n", "dofs u", "direct: first step / later [s]",
            "AMG: first step / later [s]", "later steps direct / AMG",
            f"{RUN_STEPS}-step cost direct / AMG [s]", "faster"]
    lines += [*md_head(head)]
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
        lines.append(md_row(cells))
    return lines


def difference(rows) -> list:
    """max-norm and L2 (nodal) relative differences of u and zeta, AMG against direct."""
    pairs = solver_pairs(rows)
    head = ["example", "ranks", "n", "dofs u", "t", "u: rel. diff. max / l2",
            "zeta: rel. diff. max / l2"]
    lines = [*md_head(head)]
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
        lines.append(md_row(cells))
        out.append(cells)
    return lines


def field_difference(a: dict, b: dict) -> dict:
    """name -> (max, l2) relative difference of the final nodal fields u and zeta of runs a
    and b (b against a); empty when a folder lacks its fields."""
    files = [Path(r["folder"]) / "fields_final.npz" for r in (a, b)]
    if not all(f.exists() for f in files):
        return {}
    fa, fb = (sorted_fields(f, ["u", "zeta"]) for f in files)
    out = {}
    for name in ("u", "zeta"):
        x, y = fa[name][1], fb[name][1]
        out[name] = (float(np.abs(x - y).max() / np.abs(x).max()),
                     float(np.linalg.norm(x - y) / np.linalg.norm(x)))
    return out


def variants_table(rows) -> list:
    """Each tagged run (a solver option set) against the untagged run of the same example,
    size, ranks and mode: time per step, first step, iterations and the answers' difference."""
    base = {(r["example"], r["n"], r["ranks"], r["mode"]): r for r in rows if not r["tag"]}
    head = ["example", "ranks", "n", "dofs u", "variant (options)",
            "time/step median [s] base / variant", "ratio", "first step [s] base / variant",
            "CG its base / variant", "u, zeta: rel. diff. max"]
    lines = [*md_head(head)]
    for r in rows:
        b = base.get((r["example"], r["n"], r["ranks"], r["mode"]))
        if not r["tag"] or b is None:
            continue
        col = next(iter(EXAMPLES[r["example"]][3]))
        diff = field_difference(b, r)
        cells = [r["example"], r["ranks"], r["n"], _dofs(r["dofs_u"]),
                 f"{r['tag']} (`{' '.join(r['options'])}`, {r['mode']})",
                 f"{b['step_median_s']:.3g} / {r['step_median_s']:.3g}",
                 f"{r['step_median_s'] / b['step_median_s']:.2f}",
                 f"{b['first_step_s']:.3g} / {r['first_step_s']:.3g}",
                 f"{its_text(b['its'][col])} / {its_text(r['its'][col])}",
                 ", ".join(f"{v[0]:.1e}" for v in diff.values()) or "-"]
        lines.append(md_row(cells))
    return lines


def plot(rows, path: Path):
    from damage_dolfinx.viz import figstyle
    fig, axes = figstyle.pyplot_styled().subplots(1, len(EXAMPLES), figsize=(11, 4))
    for ax, example in zip(axes, EXAMPLES):
        for (mode, ranks), style in {("auto", 1): "o-C0", ("auto", 2): "s-C1",
                                     ("direct", 1): "^:C2", ("direct", 2): "v:C3"}.items():
            sel = [r for r in rows if r["example"] == example and r["mode"] == mode
                   and r["ranks"] == ranks]
            if not sel:
                continue
            d = [r["dofs_u"] for r in sel]
            label = {"auto": "package rule", "direct": "direct only"}[mode]
            ax.loglog(d, [r["step_median_s"] for r in sel], style[:-2], color=style[-2:],
                      label=f"{label}, {ranks} rank(s): slope {fit(sel):.2f}")
        sel = [r for r in rows if r["example"] == example and r["mode"] == "auto"
               and r["ranks"] == 1]
        if sel:
            ref = np.array([sel[0]["dofs_u"], sel[-1]["dofs_u"]], float)
            ax.loglog(ref, sel[0]["step_median_s"] * ref / ref[0], color="0.6", lw=0.8,
                      label="slope 1")
        ax.set_xlabel("displacement / velocity unknowns")
        ax.set_ylabel("time per step [s]")
        ax.set_title(example)
        ax.legend(fontsize=7)
    figstyle.save(fig, path, title="2-D time per step against unknowns")


def report(out: Path, record: Path, readme: Path = None):
    every = load(out)
    rows = [r for r in every if not r["tag"]]
    record.mkdir(parents=True, exist_ok=True)
    stamp = f"{time.strftime('%Y-%m-%d')}, commit {commit()}"
    (record / "scaling.md").write_text("\n".join(
        [f"<!-- {stamp}; scaling_2d.py report -->", ""] + scaling_table(rows)) + "\n")
    (record / "efficiency.md").write_text("\n".join(efficiency_table(rows)) + "\n")
    (record / "crossover.md").write_text("\n".join(crossover_table(rows)) + "\n")
    (record / "difference.md").write_text("\n".join(difference(rows)) + "\n")
    (record / "variants.md").write_text("\n".join(variants_table(every)) + "\n")
    (record / "runs.json").write_text(json.dumps(  # paths relative to the checkout
        [{k: v.replace(f"{REPO}/", "") if k == "command" else v for k, v in r.items()
          if k != "folder"} for r in every], indent=1))
    plot(rows, record / "scaling.png")
    for name in ("scaling.md", "efficiency.md", "crossover.md", "difference.md", "variants.md"):
        print((record / name).read_text())
    if readme is not None:
        try:  # the record's name as the README (in benchmarks/) refers to it
            name = record.resolve().relative_to(readme.resolve().parent).as_posix()
        except ValueError:
            name = record.as_posix()
        done = write_readme(readme, readme_block(rows, name))
        print(f"{readme}: {'scaling block written' if done else 'no scaling block markers'}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    one = sub.add_parser("run", help="measure one size")
    one.add_argument("example", choices=list(EXAMPLES))
    one.add_argument("--n", type=int, required=True)
    one.add_argument("--ranks", type=int, default=1)
    one.add_argument("--mode", choices=MODES, default="auto")
    one.add_argument("--steps", type=int, default=None,
                     help="steps of the run (default: DEFAULT_STEPS of the example)")
    one.add_argument("--force", action="store_true")
    one.add_argument("--tag", default="", help="name of a variant (a solver option set): its "
                     "runs are compared with the untagged run of the same size")
    one.add_argument("--options", default="", help="PETSc options of the variant, one string, "
                     "e.g. '-mech_amg_rebuild_its 0'")
    rep = sub.add_parser("report", help="tables, fit and plot from the measured runs")
    rep.add_argument("--record", default=str(REPO / "benchmarks" / "reference_output"
                                             / "scaling_2d"))
    rep.add_argument("--readme", default=str(REPO / "benchmarks" / "README.md"),
                     help="the README whose scaling block (between its markers) is rewritten; "
                     "'' for none")
    for p in (one, rep):
        p.add_argument("--out", default=str(REPO / "results" / "scaling_2d"))
    args = parser.parse_args(argv)
    out = Path(args.out)
    if args.command == "report":
        report(out, Path(args.record), Path(args.readme) if args.readme else None)
        return
    target = out / "runs" / (run_name(args.example, args.n, args.ranks, args.mode, args.tag)
                             + ".json")
    if target.exists() and not args.force:
        print(f"kept {target}")
        return
    steps = args.steps or DEFAULT_STEPS[args.example]
    if steps <= FIRST_TIMED[args.example]:
        parser.error(f"--steps must exceed {FIRST_TIMED[args.example]} (the first timed step)")
    row = measure(args.example, args.n, args.ranks, args.mode, steps, out / "folders",
                  args.options.split(), args.tag)
    target.parent.mkdir(parents=True, exist_ok=True)
    target.write_text(json.dumps(row, indent=1))
    print(json.dumps({k: row[k] for k in ("example", "n", "ranks", "mode", "dofs_u", "step_s",
                                          "first_step_s", "run100_s", "its")}))


if __name__ == "__main__":
    main()
