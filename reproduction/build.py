"""``make report``: one self-contained folder ``<results>/report/`` with REPORT.html (its
images copied into ``report/images/``), REPORT.md and, with ``--pdf``, REPORT.pdf -- a document
that still reads and displays when the folder is moved or zipped.

Sources (report_sources.py), each traceable to the command that produced it: the figure runs,
the convergence studies, the thesis tables beside ours (benchmarks/reproduction/fidelity.py), the bridge
summary, the benchmark records (report_records.py), every example's assumptions (the
catalogue). The document: title block with the count of each verdict class, contents, summary
(one row per thesis table and figure with its graded verdict: report_verdicts.py, checks in
report_checks.py), known differences, the readings of the thesis data, then every section with
its figures (full resolution preferred; a quick run's caption says what differs from the full
run), thesis-beside-ours tables and assumptions. Rendering: report_doc.py; text for a reader
outside the project (thesis sections instead of line numbers, no internal codes, no machine
paths): report_text.py.
"""
from __future__ import annotations

import html
import re
import shutil
import time
from pathlib import Path

from reproduction.doc import Doc, _inline
from reproduction.records import (REPO, _bridge, _friction_cpu, _performance, _shown, _status,
                             _step_floor, _threed_scaling, _wall_times)
from reproduction.sources import (Figures, _bridge_summary, _convergence_png, _fidelity, _load_json,
                             _study_folder)
from reproduction.text import assumption, example_ref
from reproduction.classes import QUICK, Evidence, classify, counts as class_counts, headline
from reproduction.verdicts import CLASSES, category, known_differences, summary_table, table_rows
from reproduction.record import VerdictRecord

SECTION_TITLES = {
    "2.1": "Section 2.1: quasistatic elastic body with damage",
    "2.2": "Section 2.2: quasistatic Kelvin-Voigt contact with Tresca friction",
    "2.3": "Section 2.3: viscoelastic body with long memory, normal compliance",
    "2.4": "Section 2.4: elasto-viscoplastic contact, Tresca / simplified Coulomb friction",
    "3.1": "Section 3.1: dynamic Kelvin-Voigt contact, normal compliance",
    "3.2": "Section 3.2: dynamic Kelvin-Voigt contact, bilateral Tresca friction",
    "3.3": "Section 3.3: fully damageable dynamic contact",
}
#: the folder ``make report`` writes inside the results folder
FOLDER = "report"
#: the readings of the thesis data (a hand-written record; it states no verdict of its own)
READINGS = REPO / "benchmarks" / "readings.md"


def quick_difference(command: str, ex, thesis_run: str = "") -> str:
    """What a quick run is, beside the thesis's figure: its mesh, time step and final time read
    from its command, then the thesis figure's own mesh and step where the thesis states them."""
    opts = dict(re.findall(r"--(n|h|k|T) (\S+)", command))
    parts = []
    if "n" in opts:
        parts.append(f"n = {opts['n']}")
    if "h" in opts:
        parts.append(f"h = {opts['h']}")
    parts.append(f"k = {opts.get('k', f'{ex.k:g}')}")
    if "T" in opts and float(opts["T"]) != ex.T:
        parts.append(f"stops at t = {opts['T']} of T = {ex.T:g}")
    thesis = (f"the thesis's figure: {thesis_run}" if thesis_run else
              "the thesis does not state its figure's mesh")
    return f"quick run on {', '.join(parts)} ({thesis})"


def _setting_verdict(ex, quick=False):
    """A setting figure: drawn as stated, unless its geometry or boundary layout is assumed."""
    layout = [a for a in ex.literal.assumptions if re.match(
        r"(?:[\d.]+/)?G\d+[\w/]*:\s*(?:Gamma_[DNC] =|Omega =|geometry|cantilever|semicircular)", a)]
    verdict = classify(Evidence(kind="setting", quick=quick, layout_assumed="; ".join(
        assumption(a).removeprefix("assumed: ") for a in layout)))
    return verdict, ("our assumed layout" if layout else "the setting as stated in the text")


def build(results: Path) -> Path:
    """Write ``<results>/report/`` (REPORT.html with its images, REPORT.md); returns the HTML
    path."""
    from damage_dolfinx.catalogue import examples
    from reproduction import reproduce
    from reproduction.checks import judge, run_context
    from reproduction.figures import THESIS_FIGURES, mesh_drawn
    results = Path(results).resolve()
    folder = results / FOLDER
    if folder.exists():
        shutil.rmtree(folder)
    folder.mkdir(parents=True)
    doc = Doc(folder, roots=[(results, results.name), (REPO, "")])
    catalogue = {k: ex.with_reading() for k, ex in examples.catalogue().items()}
    figs = Figures(results)
    fidelity, write_fidelity = _fidelity(results)
    conv_index = _load_json(results / "convergence" / "index.json") or {}
    conv_commands = {(s["example"], s["variant"]): s["command"] for s in conv_index.get("studies", [])}
    bridge, bridge_path = _bridge_summary(results)
    readings = READINGS

    # ---- verdicts of every thesis figure and table (rows of the summary, thesis order)
    rows = table_rows(fidelity, results, _study_folder, _load_json, _sort_key)
    table_verdicts = {t["table"]: r["verdict"] for t, r in zip(fidelity["tables"], rows)}
    by_number = {t["table"]: t for t in fidelity["tables"]}
    conv_table = {"2.11": "2.4", "2.15": "2.5", "2.23": "2.6", "3.2": "3.1"}
    figure_blocks = {}
    for fig in THESIS_FIGURES:
        ex = catalogue.get(fig.example)
        found = [figs.find(f) for f in fig.files]
        paths = [(f[0], f[1]) for f in found if f]
        if fig.kind == "convergence":
            variants = ("tresca", "coulomb") if fig.example == "2.4-ex1" else ("",)
            paths = [(p, "study") for p in (_convergence_png(results, fig.example, v)
                                            for v in variants) if p]
            if fig.number in conv_table:
                numbers = ("2.6", "2.7") if fig.number == "2.23" else (conv_table[fig.number],)
                beside = [_thesis_beside_ours(results, by_number.get(n)) for n in numbers]
                if all(beside):  # the thesis's values beside ours (the study's own plot else)
                    paths = [(b, paths[0][1] if paths else "study") for b in beside]
                verdict = table_verdicts.get(conv_table[fig.number], "not comparable")
                got = f"as Table {conv_table[fig.number]}"
                if fig.number == "2.23":
                    both = [table_verdicts.get(t, "not comparable") for t in ("2.6", "2.7")]
                    verdict = both[0] if category(both[0]) == category(both[1]) else \
                        min(both, key=lambda v: -CLASSES.index(category(v)))
                    got = "as Tables 2.6 (Tresca) and 2.7 (Coulomb)"
            else:
                verdict, got = classify(Evidence(
                    statement=False, no_statement="the thesis's table is not available to this "
                    "report; our convergence plot alone (see the table row)")), "our convergence plot"
        elif fig.kind == "setting":
            verdict, got = _setting_verdict(ex, quick=bool(paths) and paths[0][1] == "quick")
            note = mesh_drawn(fig, found[0][3].get("command", "") if found and found[0] else "",
                              ex.n if ex else None)
            got += f"; {note}" if note and paths else ""
        elif fig.kind == "assumed-setting":
            verdict, got = classify(Evidence(
                kind="setting", quick=bool(paths) and paths[0][1] == "quick",
                layout_assumed="the thesis shows a sketch without dimensions; ours is an assumed "
                "geometry")), "our assumed geometry"
        else:
            context = run_context(figs.run_folder(found[0][3]) if found and found[0] else None)
            context["T_full"] = ex.T if ex else None
            command = found[0][3].get("command", "") if found and found[0] else ""
            stop = re.search(r"--T (\S+)", command)
            context["T_run"] = float(stop.group(1)) if stop else None
            context["quick"] = bool(found and found[0]) and found[0][1] == "quick"
            if bridge and fig.example == "2.1-ex3":
                context.update(hinges=bridge.get("n_mechanism_hinges", bridge.get("n_hinges")),
                               failure_load_kN=bridge.get("failure_load_kN"))
            related = [r[2] if r else None for r in (figs.find(f) for f in fig.related)]
            verdict, got, _ = judge(fig, [f[2] if f else None for f in found], related, context)
        if not paths:
            verdict, got = classify(Evidence(missing="not produced (run `make figures`)")), "-"
        quick = any(mode == "quick" for _, mode in paths) and bool(found and found[0])
        if quick and ex:
            got += (f" [{quick_difference(found[0][3].get('command', ''), ex, fig.thesis_run)}]")
        rows.append(dict(key=_sort_key(fig.number, 1), item=f"Figure {fig.number}",
                         anchor=fig.anchor, example=fig.example,
                         shows=f"{fig.shows} ({example_ref(fig.example)})", got=got,
                         verdict=verdict))
        figure_blocks.setdefault(fig.example, []).append((fig, paths, got, verdict, quick))
    rows.sort(key=lambda r: r["key"])
    # ---- the one record: every place below prints an item's verdict from it
    record = VerdictRecord()
    for r in rows:
        record.set(r["item"], r["verdict"])
    for t in fidelity["tables"]:
        t["verdict"] = record[f"Table {t['table']}"]
    counts = class_counts(verdict for _, verdict in record.items())
    _title(doc, figs, counts, len(rows))
    _contents(doc, readings)
    summary_table(doc, rows, fidelity)
    known_differences(doc, rows)
    if readings.is_file():
        doc.anchor_heading(2, "Readings of the thesis data", "readings")
        doc.para("Where the stated data of an example do not reproduce the thesis's results, a "
                 "*reading* changes as little as possible and is compared with the stated data "
                 "(`benchmarks/readings.md`).")
        doc.markdown_table(record.fill_readings(readings.read_text()))
    _sections(doc, results, catalogue, figs, fidelity, figure_blocks, conv_commands, bridge,
              bridge_path, reproduce, record)
    _wall_times(doc, figs.sources[0][1] if figs.sources else None, conv_index)
    _performance(doc, results)
    _step_floor(doc)
    _threed_scaling(doc)
    markdown = doc.to_markdown()
    fidelity_md = write_fidelity(fidelity, results / "fidelity") if write_fidelity else ""
    problems = (record.disagreements(markdown, "REPORT.md")
                + record.disagreements(fidelity_md, "fidelity.md", default_kind="Table"))
    if problems:  # a verdict stated anywhere but from the record: no report with two verdicts
        raise ValueError("the report states verdicts that differ from its record: "
                         + "; ".join(problems))
    (folder / "REPORT.md").write_text(markdown)
    page = folder / "REPORT.html"
    page.write_text(doc.to_html("damage-dolfinx: reproduction of Campo (2007)"))
    return page


def _thesis_beside_ours(results, entry):
    """The thesis's table values beside our errors (reproduction/plots.py), or None."""
    if not entry or "ratio_median" not in entry:
        return None
    from reproduction.plots import thesis_beside_ours
    return thesis_beside_ours(entry, results / "fidelity" / f"table_{entry['table'].replace('.', '_')}.png",
                              f"Table {entry['table']}: thesis (open, dashed) and ours (filled), "
                              f"{entry['study']}")


def _title(doc, figs, counts, total):
    fig_modes = ", ".join(f"{index['mode']} figure runs on {index['mpi_size']} MPI ranks "
                          f"({index.get('wall_time_s', '?')} s)" for _, index, _ in figs.sources[:1])
    quick = bool(figs.sources) and figs.sources[0][2] == "quick"
    preview = ("<p style=\"background:#fff3cd;border:1px solid #e0a800;padding:6px\"><b>Preview: judged on coarse quick runs</b> (`make figures-"
               "quick`), not on the thesis's resolution. Every verdict judged on a quick run ends "
               "in “(quick)”; run `make figures` for the verdicts a reviewer can sign.</p>"
               if counts.get("quick") else "")
    lines = "".join(f'<li class="{c}">{counts[c]} {html.escape(c)}</li>' for c in CLASSES)
    doc.raw(f'<header class="title"><h1>damage-dolfinx: reproduction of M. Campo (2007)</h1>'
            + preview.replace("`", "") +
            f"<p>M. Campo, <i>Numerical analysis and simulation of quasistatic and dynamic "
            f"contact problems with damage</i>, PhD thesis, Universidade de Santiago de "
            f"Compostela, 2007: every thesis figure and error table recomputed with DOLFINx and "
            f"set beside the thesis. Thesis references give the thesis's section, page and "
            f"example.<br>Generated {time.strftime('%Y-%m-%d %H:%M')} by <code>make report</code>; "
            f"figures: {html.escape(fig_modes or 'none yet (run make figures)')}"
            + (" (coarse quick runs)" if quick else "") + ".</p>"
            f"<p><b>What the verdicts rest on:</b> {html.escape(headline(counts))}.</p>"
            f'<ul class="counts">{lines}</ul></header>',
            f"# damage-dolfinx: reproduction of M. Campo (2007)\n\n"
            + ("**Preview: judged on coarse quick runs, not on the thesis's resolution; every "
               "verdict judged on a quick run ends in (quick).**\n\n" if counts.get("quick") else "")
            + f"Generated {time.strftime('%Y-%m-%d %H:%M')}; figures: {fig_modes or 'none'}."
            f"\n\n**{headline(counts)}**.")


def _contents(doc, readings):
    toc = [("summary", "Summary: every thesis table and figure"),
           ("differences", "Known differences")]
    if readings.is_file():
        toc.append(("readings", "Readings of the thesis data"))
    toc += [(f"sec-{s.replace('.', '-')}", t) for s, t in SECTION_TITLES.items()]
    toc += [("wall-times", "Wall times"), ("performance", "Performance"),
            ("step-floor", "Per-step cost against its floor"), ("scaling-3d", "3-D scaling")]
    doc.raw('<nav class="toc"><h2 class="first" id="contents">Contents</h2><ol>'
            + "".join(f'<li><a href="#{a}">{html.escape(t)}</a></li>' for a, t in toc)
            + "</ol></nav>", "\n".join(f"- [{t}](#{a})" for a, t in toc))


def _sections(doc, results, catalogue, figs, fidelity, figure_blocks, conv_commands, bridge,
              bridge_path, reproduce, record):
    """Every thesis section: its examples' runs, figures, tables and assumptions."""
    by_table = {t.get("study"): t for t in fidelity["tables"]}
    for section, title in SECTION_TITLES.items():
        exs = [ex for ex in catalogue.values() if ex.section == section]
        if not exs:
            continue
        doc.anchor_heading(2, title, f"sec-{section.replace('.', '-')}")
        for ex in exs:
            doc.anchor_heading(3, f"{ex.id}: {ex.title}", f"ex-{ex.id}")
            for mode, run in figs.runs(ex.id):
                doc.para(f"Run{' (' + run['variant'] + ')' if run['variant'] else ''}: "
                         f"`{run['command']}` ({_status(run)}, {run['wall_time_s']} s)"
                         + (f"; {quick_difference(run['command'], ex)}" if mode == "quick" else ""))
            thesis_files = set()
            for fig, paths, got, _, quick in figure_blocks.get(ex.id, []):
                verdict = record[f"Figure {fig.number}"]
                thesis_files.update(fig.files)
                if not paths:
                    doc.raw(f'<p id="{fig.anchor}"><b>Figure {fig.number}</b>: not produced '
                            f"in this reproduction ({_inline(verdict)}).</p>",
                            f"**Figure {fig.number}**: not produced.")
                    continue
                quote = f" Thesis: “{fig.quote}”" if fig.quote else ""
                doc.figure([p for p, _ in paths],
                           f"**Figure {fig.number}** ({example_ref(fig.example)}): "
                           f"{fig.shows}.{quote} Ours: {got}. Verdict: **{verdict}**.",
                           fig.anchor)
            for path, entry in figs.extra(ex.id, thesis_files):
                doc.image(path, f"Not a thesis figure: {entry['file']} "
                                f"({entry.get('variant') or 'final state'}).")
            for variant in (reproduce.VARIANTS.get(ex.id) or {"": {}}) if ex.convergence else ():
                name = ex.id + (f"-{variant}" if variant else "")
                if name in by_table and "ratio_median" in by_table[name]:
                    _fidelity_table(doc, by_table[name], record)
                _convergence_of(doc, results, ex.id, variant, conv_commands,
                                full=name not in by_table)
            if ex.id == "2.1-ex3" and bridge:
                _bridge(doc, bridge, bridge_path)
            if ex.id == "2.2-ex1":
                _friction_cpu(doc)
            doc.para("**Assumptions**: *assumed* = a value or layout the thesis does not give; "
                     "*reading* and *departure* = a departure from the stated data (its basis "
                     "in brackets: supported by the text, fitted, or against the text).")
            doc.items(assumption(a) for a in ex.assumptions)


#: a thesis table sits in the summary right after the figure it belongs to
TABLE_AFTER = {"2.1": "2.2", "2.4": "2.11", "2.5": "2.15", "2.6": "2.23", "2.7": "2.23",
               "3.1": "3.2", "3.2": "3.9", "3.3": "3.16"}


def _sort_key(number: str, kind: int):
    """Thesis order: figures by number, each table after the figure of TABLE_AFTER."""
    if kind == 0:
        a, b = TABLE_AFTER.get(number, number).split(".")
        return (int(a), int(b), 1, number)
    a, b = number.split(".")
    return (int(a), int(b), 0, "")


def _fidelity_table(doc, t, record):
    """The thesis's table beside ours, cell by cell, with the ratio."""
    anchor = f"table-{t['table'].replace('.', '-')}"
    ks = t["k"]
    rows = {}
    for c in t["cells"]:
        rows.setdefault(c["n"], {})[c["k"]] = c
    head = "".join(f"<th>k = {k:g}</th>" for k in ks)
    body = ""
    for n in sorted(rows):
        cells = ""
        for k in ks:
            c = rows[n].get(float(k), {})
            if "ratio" in c and "excluded" in c:
                cells += (f'<td class="ratio"><b>({c["ratio"]:.3g})</b><small>left out: '
                          f'{c["thesis"]:.4g} / {c["ours"]:.4g}</small></td>')
            elif "ratio" in c:
                cls = "good" if 0.5 <= c["ratio"] <= 2 else "bad"
                cells += (f'<td class="ratio {cls}"><b>{c["ratio"]:.3g}</b><small>'
                          f'{c["thesis"]:.4g} / {c["ours"]:.4g}</small></td>')
            else:
                cells += f'<td class="ratio"><b>-</b><small>{c.get("thesis", 0):.4g} / -</small></td>'
        body += f"<tr><th>{n}</th>{cells}</tr>"
    doc.anchor_heading(4, f"Table {t['table']} (thesis) beside ours: {t['study']}", anchor)
    doc.raw(f"<table><tr><th>n \\ k</th>{head}</tr>{body}</table>",
            markdown_cells(t))
    comp = ", ".join(f"{k} {v:.3g}" for k, v in t.get("component_medians", {}).items())
    doc.note(f"Each cell: **ratio ours / thesis** (green within [0.5, 2]), below it thesis / ours. "
             f"Thesis norm: {t['thesis_norm']}; ours: {t['our_error']} (reference n, k: thesis "
             f"{t['reference_thesis']}, ours {t['reference_ours']}). Median ratio "
             f"{t['ratio_median']:.3g}, min {t['ratio_min']:.3g}, max {t['ratio_max']:.3g}; fitted "
             f"rate in h + k: thesis {t['rate_thesis_common_cells']:.3f}, ours {t['rate_ours']:.3f}."
             + (f" Median ratio of our error components alone: {comp}." if comp else "")
             + f" Source: {t['source']} (`{_shown(Path(t['folder']))}`). Verdict: "
               f"**{record['Table ' + t['table']]}**.")


def markdown_cells(t) -> str:
    """The thesis-beside-ours table in Markdown (ratio, thesis / ours per cell)."""
    ks = t["k"]
    rows = {}
    for c in t["cells"]:
        rows.setdefault(c["n"], {})[c["k"]] = c
    cell = lambda c: (f"**{c['ratio']:.3g}** ({c['thesis']:.4g} / {c['ours']:.4g})"  # noqa: E731
                      if "ratio" in c else f"- ({c.get('thesis', 0):.4g} / -)")
    return (f"| n \\ k | " + " | ".join(f"k = {k:g}" for k in ks) + " |\n|---"
            + "|---" * len(ks) + "|\n" + "".join(
                f"| {n} | " + " | ".join(cell(rows[n].get(float(k), {})) for k in ks) + " |\n"
                for n in sorted(rows)))


def _convergence_of(doc, results, example_id, variant, commands, full=True):
    name = example_id + (f"-{variant}" if variant else "")
    folder = _study_folder(results, name)
    if folder is None:
        doc.para(f"Convergence study `{name}`: not run yet (`make convergence`).")
        return
    summary = _load_json(folder / "summary.json") or {}
    command = commands.get((example_id, variant)) or summary.get("environment", {}).get("command", "?")
    ref = summary.get("reference", {})
    doc.raw(f'<p id="study-{name}">Convergence study <code>{name}</code> (reference n = '
            f"{summary.get('ref_n')}, k = {summary.get('ref_k')}; {summary.get('mpi_size')} MPI "
            f"ranks; {summary.get('wall_time_s', 0):.0f} s, reference run "
            f"{ref.get('wall_time_s', 0):.0f} s) from <code>{_shown(folder)}</code>; command: "
            f"<code>{html.escape(command)}</code></p>", f"Convergence study `{name}`")
    if not full:
        return  # the thesis-beside-ours table above has every cell
    text = (folder / "errors.md").read_text()
    doc.markdown_table(text)
    parts = re.split(r"^## .*$", text, flags=re.M)
    tables = [re.findall(r"^\|.*\|$", p, flags=re.M) for p in parts]
    if len(tables) == 2 and tables[0] == tables[1]:
        doc.note("The final-time table equals the max-over-time table: for this study the "
                 "maximum over time of the error is attained at the final time T.")
