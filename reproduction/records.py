"""The report's benchmark records (report.py builds the document): wall times of the
reproduction, the performance record, the friction CPU comparison (thesis Tables 2.2/2.3), the
bridge failure load, the per-step cost against its floor (benchmarks/performance/step_floor.py) and the 3-D
scaling record (benchmarks/performance/threed_scaling.py). Each reads the committed output
in ``benchmarks/reference_output/`` (or the results folder) and names the command behind it.
"""
from __future__ import annotations

from pathlib import Path

from reproduction import CHECKOUT

REPO = CHECKOUT
REFERENCE = REPO / "benchmarks" / "reference_output"


def _status(entry) -> str:
    """A run's status in index.json ("completed", ...) or its exit code."""
    return entry.get("status") or f"exit {entry['returncode']}"


def _shown(folder: Path) -> str:
    return str(folder.relative_to(REPO)) if REPO in folder.parents else str(folder)


def _wall_times(doc, fig_index, conv_index):
    """Wall time of every run of this reproduction (figure runs and convergence studies)."""
    groups = (("figures", (fig_index or {}).get("runs", [])),
              ("convergence", conv_index.get("studies", [])))
    rows = [(f"{kind}: {e['example']} {e['variant']}".rstrip(), _status(e), e["wall_time_s"])
            for kind, entries in groups for e in entries]
    doc.anchor_heading(2, "Wall times of this reproduction", "wall-times")
    if not rows:
        doc.para("No run in this results folder.")
        return
    total = sum(t for _, _, t in rows)
    doc.markdown_table("| run | status | wall time [s] |\n|---|---|---|\n"
                       + "".join(f"| {name} | {status} | {t:.1f} |\n" for name, status, t in rows)
                       + f"| **total** | | **{total:.0f}** ({total / 3600:.2f} h) |\n")
    check = REFERENCE / "reproduction" / "reproduction_check.md"
    if check.is_file():
        doc.para("**The committed one-command reproduction**: `make convergence NP=2` and `make "
                 "figures NP=2` on one checkout, each once, on a quiet 2-core machine, compared "
                 "with the committed tables by `python benchmarks/reproduction/reproduction_check.py` (target: "
                 "both together within 40 minutes; every error equal to the committed one to a "
                 f"relative 1e-6). From the committed record `{check.name}`:")
        text = check.read_text()
        table = text[:text.index("\n\n")]
        doc.markdown_table(table + "\n")
        for line in text[text.index("\n\n"):].strip().splitlines():
            if line.strip():
                doc.para(line.lstrip("* "))
        _explain_check(doc, check.with_suffix(".json"))


def _explain_check(doc, record_path):
    """What the check's last line means, from its JSON record."""
    import json
    try:
        record = json.loads(record_path.read_text())
    except (OSError, ValueError):
        return
    worst = max(record["studies"], key=lambda s: s["max_relative_difference"])
    n, k, column, value, diff = worst["at"]
    doc.note(f"The check passes when every error of the new run equals the committed one to a "
             f"relative {record['tolerance']:g} (a test of repeatability, not of agreement with "
             f"the thesis). " + ("It passed." if record["passed"] else
                                 f"It failed on one cell only: {worst['study']} at n = {n}, k = "
                                 f"{k:g}, {column} = {value:.3e} differs by {diff:.1e} (relative "
                                 f"{worst['max_relative_difference']:.1e}), a rounding-level "
                                 f"difference between two runs, far below any difference a "
                                 f"verdict of this report reads."))


def _performance(doc, results):
    """Time per step vs dofs, serial and 2 ranks (benchmarks/performance/performance.py)."""
    doc.anchor_heading(2, "Performance: time per step vs dofs, serial and 2 MPI ranks",
                       "performance")
    for table in (results / "performance" / "performance.md", REFERENCE / "performance" / "performance.md"):
        if table.is_file():
            doc.para(f"`python benchmarks/performance/performance.py`, from `{_shown(table)}`.")
            doc.markdown_table(table.read_text())
            doc.note("Columns: dofs (u) = displacement unknowns; serial / 2 ranks = wall time per "
                     "time step; speed-up = serial over 2-rank time per step; `(ref)` marks the "
                     "convergence reference size.")
            return
    doc.para("No performance record.")


def _bridge(doc, s, path):
    """Failure load and hinges: from this report's figure run if it has one, else committed."""
    hinges = ", ".join(f"{h.get('angle_deg', h.get('theta_deg', '?'))}" for h in s.get("hinges", []))
    doc.para(f"**Bridge failure load {s['failure_load_kN']:.1f} kN** (thesis: damage model "
             f"{s['thesis']['damage_model_kN']} kN, contact model {s['thesis']['contact_model_kN']} kN)"
             f" at step {s['failure_step']}, load increment {s['load_increment_kN']} kN, "
             f"h = {s['h']}, k = {s['k']}; {s['n_hinges']} damaged sections (angles: {hinges}), "
             f"{s.get('n_mechanism_hinges', s['n_hinges'])} of them mechanism hinges (rotation "
             f"in the collapse step at least 0.2 x the largest); "
             f"calibration: {s.get('calibrated')}; source `{_shown(path)}` "
             f"(`benchmarks/studies/bridge_collapse.py`).")


def _friction_cpu(doc):
    explain = ("Columns: n, k = mesh and time step; Newton / Uzawa / penalty-duality s = wall "
               "time of the whole run (T = 1) per friction solver; floor s = one factorised "
               "linear solve per step plus the damage steps (the least any solver can cost); "
               "Newton/floor, Uzawa/Newton, PD/Newton = ratios of those times; friction step s = "
               "time in the friction solve only (Newton / Uzawa / PD) and the two ratios after "
               "it; Uzawa-Newton (V), PD-Newton (V) = relative V-norm distance of the final "
               "displacements to Newton's. '-' = skipped after the time budget.")
    table = REFERENCE / "friction_cpu" / "cpu.md"
    if table.is_file():
        doc.para("CPU comparison of the three friction solvers (thesis Tables 2.2/2.3; "
                 "`python benchmarks/studies/friction_cpu_2_2.py`, committed output "
                 "`benchmarks/reference_output/friction_cpu/cpu.md`):")
        doc.markdown_table(table.read_text())
        doc.note(explain)
    stick = REFERENCE / "friction_cpu_stick" / "cpu.md"
    if stick.is_file():
        doc.para("The same with stick-slip (friction bound g = 200 instead of 5, Uzawa step "
                 "rho = 1e-3 from a sweep of rho at n = 16; `python benchmarks/studies/friction_cpu_2_2.py "
                 "--set g_fric=200 rho_uzawa=1e-3`, output "
                 "`benchmarks/reference_output/friction_cpu_stick/cpu.md`):")
        doc.markdown_table(stick.read_text())
        doc.note(explain)


def _step_floor(doc):
    """Per-step cost of every problem against one SpMV / CG iteration / Cholesky solve."""
    doc.anchor_heading(2, "Per-step cost against its floor", "step-floor")
    folder = REFERENCE / "step_floor"
    # the newest record of each size: step_floor_<tag>_<date>.md, the ISO date sorts last
    tables = [(label, max(folder.glob(f"step_floor_{tag}_*.md"), default=None))
              for label, tag in (("about 4k dofs (n = 45)", "n45"),
                                 ("reference size (n = 255, 131k dofs)", "n255"))]
    tables = [(label, t) for label, t in tables if t is not None]
    if not tables:
        doc.para("No per-step profile (`python benchmarks/performance/step_floor.py`).")
        return
    doc.para("`python benchmarks/performance/step_floor.py` (serial; each problem at its own k; steps after "
             "the first two, history scalars included). The floor is measured on the vector P1 "
             "matrix M + K of the same mesh: one sparse matrix-vector product, one CG + Jacobi "
             "iteration and one Cholesky solve (PETSc's). Target: at most 5x the floor at about "
             "4k dofs and 3x at the reference size. A step of these schemes performs "
             "more than one solve (a damage and a mechanical solve, one linear solve per Newton "
             "iteration, 4-40 CG iterations): the last two columns count, from PETSc's event "
             "log, the triangular-solve pairs, SpMVs and factorisations of a step and the time "
             "PETSc spends in its numerical kernels, and give the step over its own solves and "
             "over its own arithmetic (benchmarks/README.md, 'Performance against the floor').")
    for label, table in tables:
        doc.para(f"**{label}**, from `{_shown(table)}`:")
        doc.markdown_table(table.read_text())


def _threed_scaling(doc):
    """Time per step, Krylov iterations and memory against dofs in 3-D."""
    doc.anchor_heading(2, "3-D scaling: time per step, iterations and memory against dofs",
                       "scaling-3d")
    folder = REFERENCE / "threed_scaling"
    shown = False
    for stem, label in (("scaling", "quasistatic (2.1-ex1-3d)"),
                        ("scaling_dynamic", "dynamic (3.1-ex1-3d)")):
        table, plot = folder / f"{stem}.md", folder / f"{stem}.png"
        if table.is_file():
            doc.para(f"**{label}**, `python benchmarks/performance/threed_scaling.py`, from `{_shown(table)}`:")
            doc.markdown_table(table.read_text())
            shown = True
        if plot.is_file():
            doc.image(plot, f"3-D scaling, {label}: time per step and set-up, iterations per "
                            f"solve and peak memory per rank against dofs (`{_shown(plot)}`).")
    extrapolation = folder / "extrapolation.md"
    if extrapolation.is_file():
        doc.para(f"**A 10^8-dof cluster run**, extrapolated from the fits, from "
                 f"`{_shown(extrapolation)}`:")
        doc.markdown_table(extrapolation.read_text())
    if not shown:
        doc.para("No 3-D scaling record (`python benchmarks/performance/threed_scaling.py`).")
