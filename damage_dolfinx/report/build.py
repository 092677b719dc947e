"""``make report``: one Markdown + HTML report of everything reproduced (results/REPORT.md/.html).

Sources, each traceable to the command that produced it:
* figures: ``<results>/figures/index.json`` (full mode) or ``figures-quick/index.json``;
* convergence tables: ``<results>/convergence/<study>/`` if present, else the committed outputs
  in ``benchmarks/reference_output/convergence/<study>/``;
* bridge failure load: the figure run of 2.1-ex3 or ``reference_output/bridge``;
* benchmark records (wall times, performance, friction CPU, per-step floor, 3-D scaling):
  report_records.py;
* assumptions: the catalogue (every example's list, with the PROBLEMS.md gap numbers).
The document: title block with the verdict counts, TOC, summary table (one row per thesis table
and figure, thesis order: report_figures.py and benchmarks/fidelity.py), known differences,
benchmarks/readings.md when present, then every section with its figures (full resolution
preferred, quick ones marked), thesis-beside-ours tables and assumptions. Rendering: report_doc.py.
"""
from __future__ import annotations

import html
import json
import re
import time
from pathlib import Path

from damage_dolfinx.report.doc import Doc, _inline
from damage_dolfinx.report.records import (REFERENCE, REPO, _bridge, _friction_cpu, _performance, _shown,
                             _status, _step_floor, _threed_scaling, _wall_times)
SECTION_TITLES = {
    "2.1": "Section 2.1: quasistatic elastic body with damage",
    "2.2": "Section 2.2: quasistatic Kelvin-Voigt contact with Tresca friction",
    "2.3": "Section 2.3: viscoelastic body with long memory, normal compliance",
    "2.4": "Section 2.4: elasto-viscoplastic contact, Tresca / simplified Coulomb friction",
    "3.1": "Section 3.1: dynamic Kelvin-Voigt contact, normal compliance",
    "3.2": "Section 3.2: dynamic Kelvin-Voigt contact, bilateral Tresca friction",
    "3.3": "Section 3.3: fully damageable dynamic contact",
}


def _load_json(path: Path):
    return json.loads(path.read_text()) if path.is_file() else None


def _figures_index(results: Path):
    for name in ("figures", "figures-quick"):
        index = _load_json(results / name / "index.json")
        if index:
            return results / name, index
    return None, None


def _study_folder(results: Path, name: str):
    for folder in (results / "convergence" / name, REFERENCE / "convergence" / name,
                   REFERENCE / "convergence" / f"{name}-reduced"):
        if (folder / "errors.md").is_file():
            return folder
    return None


def _fidelity(results: Path):
    """benchmarks/fidelity.py's comparison (None if the script is absent, e.g. an installed
    package without the repository)."""
    import importlib.util
    script = REPO / "benchmarks" / "fidelity.py"
    if not script.is_file():
        return None
    spec = importlib.util.spec_from_file_location("damage_dolfinx_fidelity", script)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    result = module.compare(results)
    module.write(result, results / "fidelity")
    return result


class Figures:
    """Where each PNG comes from: the full-resolution run if it has it, else the quick run
    (marked), with the panel data (.npz) of field figures for the verdicts."""

    def __init__(self, results: Path):
        self.sources = []
        for name, mode in (("figures", "full"), ("figures-quick", "quick")):
            index = _load_json(results / name / "index.json")
            if index:
                self.sources.append((results / name, index, mode))
        self.results = results

    def find(self, file):
        """(png path, mode, npz path or None, index entry) of the best source, or None."""
        for folder, index, mode in self.sources:
            if (folder / file).is_file():
                entry = next((f for f in index["figures"] if f["file"] == file), {})
                return folder / file, mode, self._npz(folder, index, entry), entry
        return None

    def _npz(self, folder, index, entry):
        run = next((r for r in index["runs"] if r["example"] == entry.get("example")
                    and r["variant"] == entry.get("variant")), None)
        if run is None or not entry.get("source"):
            return None
        for base in (Path(run["folder"]), folder / "runs" / Path(run["folder"]).name):
            npz = base / Path(entry["source"]).with_suffix(".panel.npz")
            if npz.is_file():
                return npz
        return None

    def run_folder(self, entry):
        """The run folder behind a figure entry of an index (None if unknown)."""
        for folder, index, _ in self.sources:
            run = next((r for r in index["runs"] if r["example"] == entry.get("example")
                        and r["variant"] == entry.get("variant")), None)
            if run:
                for base in (Path(run["folder"]), folder / "runs" / Path(run["folder"]).name):
                    if base.is_dir():
                        return base
        return None

    def runs(self, example):
        return [(mode, r) for _, index, mode in self.sources[:1] for r in index["runs"]
                if r["example"] == example]

    def extra(self, example, thesis_files):
        """Non-thesis PNGs of an example (best source only), without the other variants'
        copies of a thesis figure (e.g. the Coulomb run's copy of the setting 2.22)."""
        stems = {re.sub(r"_(tresca|coulomb|undamaged|damaged|a|b)$", "", Path(f).stem)
                 for f in thesis_files}
        for folder, index, mode in self.sources[:1]:
            return [(folder / f["file"], f) for f in index["figures"] if f["example"] == example
                    and f["file"] not in thesis_files and (folder / f["file"]).is_file()
                    and re.sub(r"_(tresca|coulomb|undamaged|damaged|a|b)$", "",
                               Path(f["file"]).stem) not in stems]
        return []


def _verdict_class(verdict: str) -> str:
    return "v-reproduced" if verdict.startswith("reproduced") else \
        "v-differs" if verdict.startswith(("differs", "magnitude", "rate")) else "v-not"


def _category(verdict: str) -> str:
    return {"v-reproduced": "reproduced", "v-differs": "differs"}.get(
        _verdict_class(verdict), "not comparable")


def _convergence_png(results: Path, example, variant):
    name = example + (f"-{variant}" if variant else "")
    folder = _study_folder(results, name)
    return folder / "convergence.png" if folder and (folder / "convergence.png").is_file() else None


def _bridge_summary(results: Path):
    for path in (results / "figures" / "runs" / "bridge_collapse" / "bridge_summary.json",
                 results / "figures-quick" / "runs" / "bridge_collapse" / "bridge_summary.json",
                 REFERENCE / "bridge" / "bridge_summary.json"):
        s = _load_json(path)
        if s:
            return s, path
    return None, None


def build(results: Path) -> Path:
    """Write results/REPORT.md and results/REPORT.html; returns the HTML path."""
    from damage_dolfinx.catalogue import examples
    from damage_dolfinx.report import reproduce
    from damage_dolfinx.report.figures import THESIS_FIGURES, judge, run_context
    results = Path(results).resolve()
    results.mkdir(parents=True, exist_ok=True)
    doc = Doc(results)
    catalogue = examples.catalogue()
    figs = Figures(results)
    fidelity = _fidelity(results) or {"tables": []}
    conv_index = _load_json(results / "convergence" / "index.json") or {}
    conv_commands = {(s["example"], s["variant"]): s["command"] for s in conv_index.get("studies", [])}
    bridge, bridge_path = _bridge_summary(results)
    readings = REPO / "benchmarks" / "readings.md"

    # ---- verdicts of every thesis figure and table (rows of the summary, thesis order)
    rows = []
    for t in fidelity["tables"]:
        got = (f"median ratio ours/thesis {t['ratio_median']:.3g} (min {t['ratio_min']:.3g}, max "
               f"{t['ratio_max']:.3g}) over {t['n_common']} cells; rate {t['rate_ours']:.2f} vs "
               f"{t['rate_thesis_common_cells']:.2f}" if "ratio_median" in t else "no study")
        rows.append(dict(key=_sort_key(t["table"], 0), item=f"Table {t['table']}",
                         anchor=f"table-{t['table'].replace('.', '-')}", example=t.get("study", ""),
                         shows=f"errors of {t['example']} ({t.get('thesis_norm', '')})", got=got,
                         verdict=t["verdict"]))
    for number, study in (("2.1", "2.1-ex1"), ("3.3", "3.3-ex1")):
        folder = _study_folder(results, study)
        rate = ((_load_json(folder / "summary.json") or {}).get("rates", {}).get("h_plus_k_all")
                if folder else None)
        rows.append(dict(key=_sort_key(number, 0), item=f"Table {number}", anchor=f"study-{study}",
                         example=study, shows="errors (withheld from us on purpose: a control)",
                         got=f"our study: rate {rate:.2f} in h + k" if rate else "no study",
                         verdict="not comparable (thesis table withheld)"))
    table_verdicts = {t["table"]: t["verdict"] for t in fidelity["tables"]}
    conv_table = {"2.11": "2.4", "2.15": "2.5", "2.23": "2.6", "3.2": "3.1"}
    figure_blocks = {}
    for fig in THESIS_FIGURES:
        found = [figs.find(f) for f in fig.files]
        paths = [(f[0], f[1]) for f in found if f]
        if fig.kind == "convergence":
            variants = ("tresca", "coulomb") if fig.example == "2.4-ex1" else ("",)
            paths = [(p, "study") for p in (_convergence_png(results, fig.example, v)
                                            for v in variants) if p]
            if fig.number in conv_table:
                verdict = table_verdicts.get(conv_table[fig.number], "not comparable")
                got = f"as Table {conv_table[fig.number]}"
                if fig.number == "2.23":
                    verdict = table_verdicts.get("2.6", "") + " / " + table_verdicts.get("2.7", "")
                    verdict = "reproduced" if verdict == "reproduced / reproduced" else \
                        "differs: " + verdict
            else:
                verdict, got = "not comparable (thesis table withheld)", "our convergence plot"
        else:
            context = run_context(figs.run_folder(found[0][3]) if found and found[0] else None)
            if bridge and fig.example == "2.1-ex3":
                context.update(hinges=bridge.get("n_mechanism_hinges", bridge.get("n_hinges")),
                               failure_load_kN=bridge.get("failure_load_kN"))
            verdict, got, failed = judge(fig, [f[2] if f else None for f in found], context)
            if not paths:
                verdict, got = "not comparable (not produced: run `make figures`)", "-"
            elif failed:
                verdict = "differs: " + "; ".join(f"not {x}" for x in failed)
        quick = any(mode == "quick" for _, mode in paths)
        if quick:
            got += " [quick run: coarse mesh]"
        rows.append(dict(key=_sort_key(fig.number, 1), item=f"Figure {fig.number}",
                         anchor=fig.anchor, example=fig.example,
                         shows=f"{fig.shows} (thesis lines {fig.lines})", got=got, verdict=verdict))
        figure_blocks.setdefault(fig.example, []).append((fig, paths, got, verdict, quick))
    rows.sort(key=lambda r: r["key"])
    counts = {c: sum(_category(r["verdict"]) == c for r in rows)
              for c in ("reproduced", "differs", "not comparable")}

    # ---- title block, summary, TOC
    fig_modes = ", ".join(f"`{folder.name}` ({index['mode']}, {index['mpi_size']} ranks, "
                          f"{index.get('wall_time_s', '?')} s)" for folder, index, _ in figs.sources)
    doc.raw(f'<header class="title"><h1>damage-dolfinx: reproduction of M. Campo (2007)</h1>'
            f"<p>Numerical analysis and simulation of quasistatic and dynamic contact problems "
            f"with damage — every thesis figure and error table recomputed with DOLFINx and "
            f"set beside the thesis.<br>Generated {time.strftime('%Y-%m-%d %H:%M')} by "
            f"<code>make report</code> from <code>{html.escape(str(results))}</code>. Figures: "
            f"{_inline(fig_modes or 'none yet (run make figures)')}. Thesis tables: "
            f"<code>{html.escape(fidelity.get('tables_file', '-'))}</code>.</p>"
            f"<p><b>{counts['reproduced']} reproduced, {counts['differs']} differ, "
            f"{counts['not comparable']} not comparable</b> (of {len(rows)} thesis tables and "
            f"figures).</p></header>",
            f"# damage-dolfinx: reproduction of M. Campo (2007)\n\nGenerated "
            f"{time.strftime('%Y-%m-%d %H:%M')} from `{results}`. Figures: {fig_modes or 'none'}."
            f"\n\n**{counts['reproduced']} reproduced, {counts['differs']} differ, "
            f"{counts['not comparable']} not comparable** (of {len(rows)}).")
    toc = [("summary", "Summary: every thesis table and figure"),
           ("differences", "Known differences")]
    if readings.is_file():
        toc.append(("readings", "Readings of the thesis data (benchmarks/readings.md)"))
    toc += [(f"sec-{s.replace('.', '-')}", t) for s, t in SECTION_TITLES.items()]
    toc += [("wall-times", "Wall times"), ("performance", "Performance"),
            ("step-floor", "Per-step cost against its floor"), ("scaling-3d", "3-D scaling")]
    doc.raw('<nav class="toc"><h2 class="first" id="contents">Contents</h2><ol>'
            + "".join(f'<li><a href="#{a}">{html.escape(t)}</a></li>' for a, t in toc)
            + "</ol></nav>", "\n".join(f"- [{t}](#{a})" for a, t in toc))
    _summary_table(doc, rows, fidelity)
    _known_differences(doc, rows)
    if readings.is_file():
        doc.anchor_heading(2, "Readings of the thesis data", "readings")
        doc.para(f"From `{_shown(readings)}` (per-example data readings and verdicts).")
        doc.markdown_table(readings.read_text())

    # ---- sections in thesis order
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
                         f"`{run['command']}` ({_status(run)}, {run['wall_time_s']} s)")
            thesis_files = set()
            for fig, paths, got, verdict, quick in figure_blocks.get(ex.id, []):
                thesis_files.update(fig.files)
                if not paths:
                    doc.raw(f'<p id="{fig.anchor}"><b>Figure {fig.number}</b>: not produced '
                            f"in this reproduction ({_inline(verdict)}).</p>",
                            f"**Figure {fig.number}**: not produced.")
                    continue
                doc.figure([p for p, _ in paths],
                           f"**Figure {fig.number}** (thesis lines {fig.lines}). Thesis: "
                           f"{fig.shows}. Ours: {got}. Verdict: **{verdict}**."
                           + (" *Quick run (coarse mesh) shown: no full-resolution figure in this "
                              "reproduction.*" if quick else ""), fig.anchor)
            for path, entry in figs.extra(ex.id, thesis_files):
                doc.image(path, f"Not a thesis figure: {entry['file']} "
                                f"({entry.get('variant') or 'final state'}).")
            for variant in (reproduce.VARIANTS.get(ex.id) or {"": {}}) if ex.convergence else ():
                name = ex.id + (f"-{variant}" if variant else "")
                if name in by_table and "ratio_median" in by_table[name]:
                    _fidelity_table(doc, by_table[name])
                _convergence_of(doc, results, ex.id, variant, conv_commands,
                                full=name not in by_table)
            if ex.id == "2.1-ex3" and bridge:
                _bridge(doc, bridge, bridge_path)
            if ex.id == "2.2-ex1":
                _friction_cpu(doc)
            doc.para("**Assumptions** (PROBLEMS.md gap numbers):")
            doc.items(ex.assumptions)
    _wall_times(doc, figs.sources[0][1] if figs.sources else None, conv_index)
    _performance(doc, results)
    _step_floor(doc)
    _threed_scaling(doc)
    md, page = results / "REPORT.md", results / "REPORT.html"
    md.write_text(doc.to_markdown())
    page.write_text(doc.to_html("damage-dolfinx: reproduction of Campo (2007)"))
    return page


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


def _summary_table(doc, rows, fidelity):
    doc.anchor_heading(2, "Summary: every thesis table and figure", "summary")
    doc.para("One row per thesis table and figure, in thesis order. *Thesis* is what the thesis "
             "text says the item shows (thesis.txt line numbers); *ours* is measured on our "
             "output (tables: benchmarks/fidelity.py; figures: the figure's own data); the verdict "
             "rule is stated under the table.")
    body = "".join(
        f'<tr><td class="l"><a href="#{r["anchor"]}">{html.escape(r["item"])}</a></td>'
        f'<td class="l">{html.escape(r["example"])}</td><td class="l">{_inline(r["shows"])}</td>'
        f'<td class="l">{_inline(r["got"])}</td>'
        f'<td class="l {_verdict_class(r["verdict"])}">{_inline(r["verdict"])}</td></tr>'
        for r in rows)
    md = "| item | example | thesis | ours | verdict |\n|---|---|---|---|---|\n" + "".join(
        f"| [{r['item']}](#{r['anchor']}) | {r['example']} | {r['shows']} | {r['got']} | "
        f"{r['verdict']} |\n" for r in rows)
    doc.raw('<table class="summary"><tr><th class="l">item</th><th class="l">example</th>'
            '<th class="l">what the thesis shows</th><th class="l">what we get</th>'
            f'<th class="l">verdict</th></tr>{body}</table>', md)
    doc.note("Tables: " + fidelity.get("criteria", "") + ". Figures: *reproduced* when every "
             "check derived from the thesis sentence holds on our figure's data (listed in the "
             "'differs' verdicts when one fails); settings are reproduced when geometry and "
             "boundary parts are the stated ones; *not comparable*: no measurable statement, a "
             "withheld table, an assumed geometry or no output.")


def _known_differences(doc, rows):
    doc.anchor_heading(2, "Known differences", "differences")
    differ = [r for r in rows if _category(r["verdict"]) == "differs"]
    if not differ:
        doc.para("None: every comparable item is reproduced.")
        return
    doc.items(f"[{r['item']}](#{r['anchor']}) ({r['example']}): {r['verdict']}. Ours: {r['got']}."
              for r in differ)
    doc.para("The open readings of the thesis data behind these differences (loads, damage "
             "data, norms) are studied in issue 16; see the readings section when present.")


def _fidelity_table(doc, t):
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
            if "ratio" in c:
                cls = "good" if 0.5 <= c["ratio"] <= 2 else "bad"
                cells += (f'<td class="ratio {cls}"><b>{c["ratio"]:.3g}</b><small>'
                          f'{c["thesis"]:.4g} / {c["ours"]:.4g}</small></td>')
            else:
                cells += f'<td class="ratio"><b>-</b><small>{c.get("thesis", 0):.4g} / -</small></td>'
        body += f"<tr><th>{n}</th>{cells}</tr>"
    doc.anchor_heading(4, f"Table {t['table']} (thesis) beside ours: {t['study']}", anchor)
    doc.raw(f"<table><tr><th>n \\ k</th>{head}</tr>{body}</table>",
            f"Table {t['table']}: see fidelity.md")
    comp = ", ".join(f"{k} {v:.3g}" for k, v in t.get("component_medians", {}).items())
    doc.note(f"Each cell: **ratio ours / thesis** (green within [0.5, 2]), below it thesis / ours. "
             f"Thesis norm: {t['thesis_norm']}; ours: {t['our_error']} (reference n, k: thesis "
             f"{t['reference_thesis']}, ours {t['reference_ours']}). Median ratio "
             f"{t['ratio_median']:.3g}, min {t['ratio_min']:.3g}, max {t['ratio_max']:.3g}; fitted "
             f"rate in h + k: thesis {t['rate_thesis_common_cells']:.3f}, ours {t['rate_ours']:.3f}."
             + (f" Median ratio of our error components alone: {comp}." if comp else "")
             + f" Source: {t['source']} (`{_shown(Path(t['folder']))}`). Verdict: **{t['verdict']}**.")


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
