"""``make report``: one Markdown + HTML report of everything reproduced (results/REPORT.md/.html).

Sources, each traceable to the command that produced it:
* figures: ``<results>/figures/index.json`` (full mode) or ``figures-quick/index.json``;
* convergence tables: ``<results>/convergence/<study>/`` if present, else the committed outputs
  in ``benchmarks/reference_output/convergence/<study>/``;
* bridge failure load: the figure run of 2.1-ex3 or ``reference_output/bridge``;
* friction CPU comparison: ``reference_output/friction_cpu/cpu.md`` and ``friction_cpu_stick/cpu.md``
  (benchmarks/friction_cpu_2_2.py);
* assumptions: the catalogue (every example's list, with the PROBLEMS.md gap numbers).
The HTML is produced from the same blocks (no Markdown library needed).
"""
from __future__ import annotations

import html
import json
import os
import re
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
REFERENCE = REPO / "benchmarks" / "reference_output"
SECTION_TITLES = {
    "2.1": "Section 2.1: quasistatic elastic body with damage",
    "2.2": "Section 2.2: quasistatic Kelvin-Voigt contact with Tresca friction",
    "2.3": "Section 2.3: viscoelastic body with long memory, normal compliance",
    "2.4": "Section 2.4: elasto-viscoplastic contact, Tresca / simplified Coulomb friction",
    "3.1": "Section 3.1: dynamic Kelvin-Voigt contact, normal compliance",
    "3.2": "Section 3.2: dynamic Kelvin-Voigt contact, bilateral Tresca friction",
    "3.3": "Section 3.3: fully damageable dynamic contact",
}


class Doc:
    """Blocks rendered both as Markdown and as HTML."""

    def __init__(self, base: Path):
        self.base, self.blocks = base, []

    def heading(self, level, text):
        self.blocks.append(("h", level, text))

    def para(self, text):
        self.blocks.append(("p", text))

    def code(self, text):
        self.blocks.append(("code", text))

    def image(self, path: Path, caption):
        self.blocks.append(("img", os.path.relpath(path, self.base), caption))

    def items(self, lines):
        self.blocks.append(("ul", list(lines)))

    def markdown_table(self, text):
        """Copy a Markdown file's content (tables and paragraphs)."""
        self.blocks.append(("md", text))

    # -- rendering
    def to_markdown(self) -> str:
        out = []
        for b in self.blocks:
            if b[0] == "h":
                out.append("#" * b[1] + " " + b[2])
            elif b[0] == "p":
                out.append(b[1])
            elif b[0] == "code":
                out.append("```\n" + b[1] + "\n```")
            elif b[0] == "img":
                out.append(f"![{b[2]}]({b[1]})\n\n*{b[2]}*")
            elif b[0] == "ul":
                out.append("\n".join(f"- {line}" for line in b[1]))
            elif b[0] == "md":
                out.append(_demote_headings(b[1]))
        return "\n\n".join(out) + "\n"

    def to_html(self, title) -> str:
        body = []
        for b in self.blocks:
            if b[0] == "h":
                body.append(f"<h{b[1]}>{_inline(b[2])}</h{b[1]}>")
            elif b[0] == "p":
                body.append(f"<p>{_inline(b[1])}</p>")
            elif b[0] == "code":
                body.append(f"<pre><code>{html.escape(b[1])}</code></pre>")
            elif b[0] == "img":
                body.append(f'<figure><img src="{html.escape(b[1])}" alt="{html.escape(b[2])}">'
                            f"<figcaption>{_inline(b[2])}</figcaption></figure>")
            elif b[0] == "ul":
                body.append("<ul>" + "".join(f"<li>{_inline(x)}</li>" for x in b[1]) + "</ul>")
            elif b[0] == "md":
                body.append(_markdown_to_html(_demote_headings(b[1])))
        return HTML_TEMPLATE.format(title=html.escape(title), body="\n".join(body))


def _inline(text) -> str:
    text = html.escape(text)
    text = re.sub(r"`([^`]+)`", r"<code>\1</code>", text)
    return re.sub(r"\*\*([^*]+)\*\*", r"<b>\1</b>", text)


def _demote_headings(text) -> str:
    return re.sub(r"^(#+) ", lambda m: "#" * min(6, len(m.group(1)) + 3) + " ", text, flags=re.M)


def _markdown_to_html(text) -> str:
    """Headings, pipe tables and paragraphs (the subset our tables use)."""
    out, lines, i = [], text.splitlines(), 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("|"):
            rows = []
            while i < len(lines) and lines[i].startswith("|"):
                cells = [c.strip() for c in lines[i].strip().strip("|").split("|")]
                if not all(set(c) <= set("-: ") for c in cells):
                    rows.append(cells)
                i += 1
            head, *rest = rows
            out.append("<table><tr>" + "".join(f"<th>{_inline(c)}</th>" for c in head) + "</tr>"
                       + "".join("<tr>" + "".join(f"<td>{_inline(c)}</td>" for c in r) + "</tr>"
                                 for r in rest) + "</table>")
            continue
        m = re.match(r"^(#+) (.*)", line)
        if m:
            out.append(f"<h{len(m.group(1))}>{_inline(m.group(2))}</h{len(m.group(1))}>")
        elif line.strip():
            out.append(f"<p>{_inline(line)}</p>")
        i += 1
    return "\n".join(out)


HTML_TEMPLATE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<style>
body {{ font-family: sans-serif; max-width: 70em; margin: 2em auto; line-height: 1.4; }}
img {{ max-width: 100%; border: 1px solid #ccc; }}
table {{ border-collapse: collapse; margin: 1em 0; font-size: 90%; }}
td, th {{ border: 1px solid #bbb; padding: 0.2em 0.5em; text-align: right; }}
pre {{ background: #f4f4f4; padding: 0.5em; overflow-x: auto; }}
figcaption {{ font-style: italic; color: #444; }}
</style>
<script>
// marks every image as loaded or broken (checked by the test suite in headless Chromium)
window.addEventListener("load", function () {{
  var imgs = document.images, ok = 0;
  for (var i = 0; i < imgs.length; i++) {{
    var good = imgs[i].complete && imgs[i].naturalWidth > 0;
    imgs[i].setAttribute("data-loaded", good ? "yes" : "no");
    if (good) ok++;
  }}
  document.body.setAttribute("data-images", ok + "/" + imgs.length);
}});
</script></head>
<body>
{body}
</body></html>
"""


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


def build(results: Path) -> Path:
    """Write results/REPORT.md and results/REPORT.html; returns the HTML path."""
    from . import examples, reproduce
    results = Path(results).resolve()
    results.mkdir(parents=True, exist_ok=True)
    doc = Doc(results)
    catalogue = examples.catalogue()
    fig_dir, fig_index = _figures_index(results)
    conv_index = _load_json(results / "convergence" / "index.json") or {}
    conv_commands = {(s["example"], s["variant"]): s["command"] for s in conv_index.get("studies", [])}

    doc.heading(1, "damage-dolfinx: reproduction of Campo (2007)")
    doc.para(f"Generated {time.strftime('%Y-%m-%d %H:%M')} by `make report` from the folder "
             f"`{results}`. Figures: "
             + (f"`{fig_dir.name}` ({fig_index['mode']} mode, {fig_index['mpi_size']} MPI ranks, "
                f"{fig_index.get('wall_time_s', '?')} s)" if fig_index else "none yet (run `make figures`)")
             + ". Convergence: " + (f"`results/convergence` ({conv_index.get('wall_time_s', '?')} s)"
                                    if conv_index else "committed outputs in "
                                    "`benchmarks/reference_output/convergence` (run `make convergence`)."))
    for section, title in SECTION_TITLES.items():
        exs = [ex for ex in catalogue.values() if ex.section == section]
        if not exs:
            continue
        doc.heading(2, title)
        for ex in exs:
            doc.heading(3, f"{ex.id}: {ex.title}")
            _figures_of(doc, ex.id, fig_dir, fig_index)
            for variant in (reproduce.VARIANTS.get(ex.id) or {"": {}}) if ex.convergence else ():
                _convergence_of(doc, results, ex.id, variant, conv_commands)
            if ex.id == "2.1-ex3":
                _bridge(doc, results)
            if ex.id == "2.2-ex1":
                _friction_cpu(doc)
            doc.para("**Assumptions** (PROBLEMS.md gap numbers):")
            doc.items(ex.assumptions)
    _wall_times(doc, fig_index, conv_index)
    _performance(doc, results)
    md, page = results / "REPORT.md", results / "REPORT.html"
    md.write_text(doc.to_markdown())
    page.write_text(doc.to_html("damage-dolfinx report"))
    return page


def _status(entry) -> str:
    """A run's status in index.json ("completed", ...) or its exit code."""
    return entry.get("status") or f"exit {entry['returncode']}"


def _wall_times(doc, fig_index, conv_index):
    """Wall time of every run of this reproduction (figure runs and convergence studies)."""
    groups = (("figures", (fig_index or {}).get("runs", [])),
              ("convergence", conv_index.get("studies", [])))
    rows = [(f"{kind}: {e['example']} {e['variant']}".rstrip(), _status(e), e["wall_time_s"])
            for kind, entries in groups for e in entries]
    if not rows:
        return
    doc.heading(2, "Wall times of this reproduction")
    total = sum(t for _, _, t in rows)
    doc.markdown_table("| run | status | wall time [s] |\n|---|---|---|\n"
                       + "".join(f"| {name} | {status} | {t:.1f} |\n" for name, status, t in rows)
                       + f"| **total** | | **{total:.0f}** ({total / 3600:.2f} h) |\n")


def _performance(doc, results):
    """Time per step vs dofs, serial and 2 ranks (benchmarks/performance.py)."""
    for table in (results / "performance" / "performance.md", REFERENCE / "performance" / "performance.md"):
        if table.is_file():
            doc.heading(2, "Performance: time per step vs dofs, serial and 2 MPI ranks")
            doc.para(f"`python benchmarks/performance.py`, from `{_shown(table)}`; the speed-up is "
                     "serial over 2-rank time per step, `(ref)` marks the convergence reference size.")
            doc.markdown_table(table.read_text())
            return


def _figures_of(doc, example_id, fig_dir, fig_index):
    if not fig_index:
        return
    for run in fig_index["runs"]:
        if run["example"] == example_id:
            status = _status(run)
            doc.para(f"Run{' (' + run['variant'] + ')' if run['variant'] else ''}: `{run['command']}`"
                     f" ({status}, {run['wall_time_s']} s)")
    for fig in fig_index["figures"]:
        if fig["example"] == example_id and (fig_dir / fig["file"]).is_file():
            caption = f"{fig['file']}: {fig.get('title') or example_id}"
            if fig.get("variant"):
                caption += f" ({fig['variant']})"
            doc.image(fig_dir / fig["file"], caption)


def _convergence_of(doc, results, example_id, variant, commands):
    name = example_id + (f"-{variant}" if variant else "")
    folder = _study_folder(results, name)
    if folder is None:
        doc.para(f"Convergence study `{name}`: not run yet (`make convergence`).")
        return
    summary = _load_json(folder / "summary.json") or {}
    command = commands.get((example_id, variant)) or summary.get("environment", {}).get("command", "?")
    ref = summary.get("reference", {})
    doc.para(f"Convergence study `{name}` (reference n = {summary.get('ref_n')}, k = "
             f"{summary.get('ref_k')}; {summary.get('mpi_size')} MPI ranks; total "
             f"{summary.get('wall_time_s', 0):.0f} s, reference run {ref.get('wall_time_s', 0):.0f} s), "
             f"from `{_shown(folder)}`; "
             f"command: `{command}`")
    doc.markdown_table((folder / "errors.md").read_text())
    if (folder / "convergence.png").is_file():
        doc.image(folder / "convergence.png", f"{name}: error against h + k with the fitted rate")


def _shown(folder: Path) -> str:
    return str(folder.relative_to(REPO)) if REPO in folder.parents else str(folder)


def _bridge(doc, results):
    """Failure load and hinges: from this report's figure run if it has one, else committed."""
    for path in (results / "figures" / "runs" / "bridge_collapse" / "bridge_summary.json",
                 results / "figures-quick" / "runs" / "bridge_collapse" / "bridge_summary.json",
                 REFERENCE / "bridge" / "bridge_summary.json"):
        s = _load_json(path)
        if s:
            break
    else:
        return
    hinges = ", ".join(f"{h.get('angle_deg', h.get('theta_deg', '?'))}" for h in s.get("hinges", []))
    doc.para(f"**Bridge failure load {s['failure_load_kN']:.1f} kN** (thesis: damage model "
             f"{s['thesis']['damage_model_kN']} kN, contact model {s['thesis']['contact_model_kN']} kN)"
             f" at step {s['failure_step']}, load increment {s['load_increment_kN']} kN, "
             f"h = {s['h']}, k = {s['k']}, {s['n_hinges']} hinges (angles: {hinges}); "
             f"calibration: {s.get('calibrated')}; source `{_shown(path)}` "
             f"(`benchmarks/bridge_collapse.py`).")


def _friction_cpu(doc):
    table = REFERENCE / "friction_cpu" / "cpu.md"
    if table.is_file():
        doc.para("CPU comparison of the three friction solvers (Tables 2.2/2.3; "
                 "`python benchmarks/friction_cpu_2_2.py`, committed output "
                 "`benchmarks/reference_output/friction_cpu/cpu.md`):")
        doc.markdown_table(table.read_text())
    stick = REFERENCE / "friction_cpu_stick" / "cpu.md"
    if stick.is_file():
        doc.para("The same with stick-slip (friction bound g = 200 instead of 5, Uzawa step "
                 "rho = 1e-3 from the G8 sweep at n = 16; `python benchmarks/friction_cpu_2_2.py "
                 "--set g_fric=200 rho_uzawa=1e-3`, output "
                 "`benchmarks/reference_output/friction_cpu_stick/cpu.md`):")
        doc.markdown_table(stick.read_text())
