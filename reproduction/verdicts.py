"""The summary rows of the report (one per thesis table and figure) and their table; the
classes and their rules are in reproduction/classes.py (one rule per class, applied by code).
"""
from __future__ import annotations

import html

from reproduction.classes import CLASSES, RULES, Evidence, category, classify, headline  # noqa: F401
from reproduction.doc import _inline

CSS = {"reproduced": "v-reproduced", "reproduced under a reading": "v-reading",
       "drawn as stated": "v-assumed", "setting assumed": "v-assumed",
       "not visible in this figure": "v-invisible", "differs": "v-differs",
       "not comparable": "v-not"}


def md_cell(text: str) -> str:
    """Text in a Markdown table cell (its norms' bars escaped: ||u|| would split the cell)."""
    return text.replace("|", "\\|")


def table_rows(fidelity, results, study_folder, load_json, sort_key):
    rows = []
    for t in fidelity["tables"]:
        got = (f"median ratio ours/thesis {t['ratio_median']:.3g} (min {t['ratio_min']:.3g}, max "
               f"{t['ratio_max']:.3g}) over {t['n_common']} of the thesis's {t['n_thesis']} cells; "
               f"rate {t['rate_ours']:.2f} vs {t['rate_thesis_common_cells']:.2f}"
               + "".join(f" (left out: {x})" for x in t.get("excluded", []))
               if "ratio_median" in t else "no study")
        rows.append(dict(key=sort_key(t["table"], 0), item=f"Table {t['table']}",
                         anchor=f"table-{t['table'].replace('.', '-')}", example=t.get("study", ""),
                         shows=f"errors of {t['example']} ({t.get('thesis_norm', '')})", got=got,
                         verdict=t["verdict"]))
    for number, study in (("2.1", "2.1-ex1"), ("3.3", "3.3-ex1")):
        folder = study_folder(results, study)
        rate = ((load_json(folder / "summary.json") or {}).get("rates", {}).get("h_plus_k_all")
                if folder else None)
        rows.append(dict(key=sort_key(number, 0), item=f"Table {number}", anchor=f"study-{study}",
                         example=study, shows="errors against h + k",
                         got=f"our study: rate {rate:.2f} in h + k" if rate else "no study",
                         verdict=classify(Evidence(
                             kind="table", statement=False,
                             no_statement="the thesis's table is not available to this report; "
                                          "our errors and rate are shown alone"))))
    return rows


def summary_table(doc, rows, fidelity):
    doc.anchor_heading(2, "Summary: every thesis table and figure", "summary")
    doc.para("One row per thesis table and figure, in thesis order. *Thesis* is what the thesis "
             "says the item shows (where: section, page and example of the thesis); *ours* is "
             "measured on our output (tables: our convergence studies; figures: the figure's own "
             "data). The classes are explained under the table.")
    body = "".join(
        f'<tr><td class="l"><a href="#{r["anchor"]}">{html.escape(r["item"])}</a></td>'
        f'<td class="l">{html.escape(r["example"])}</td><td class="l">{_inline(r["shows"])}</td>'
        f'<td class="l">{_inline(r["got"])}</td>'
        f'<td class="l {CSS[category(r["verdict"])]}">{_inline(r["verdict"])}</td></tr>'
        for r in rows)
    md = "| item | example | thesis | ours | verdict |\n|---|---|---|---|---|\n" + "".join(
        f"| [{r['item']}](#{r['anchor']}) | {r['example']} | {md_cell(r['shows'])} | "
        f"{md_cell(r['got'])} | {md_cell(r['verdict'])} |\n" for r in rows)
    doc.raw('<table class="summary"><tr><th class="l">item</th><th class="l">example</th>'
            '<th class="l">what the thesis shows</th><th class="l">what we get</th>'
            f'<th class="l">verdict</th></tr>{body}</table>', md)
    doc.note("**Classes**, one rule each, applied in this order (the first that applies): "
             + " ".join(f"*{c}*: {RULES[c]}." for c in ("not comparable", "drawn as stated",
                                                        "setting assumed", "differs",
                                                        "not visible in this figure",
                                                        "reproduced under a reading",
                                                        "reproduced"))
             + " A verdict ending in *(quick)* is judged on a coarse quick run. Departures: "
             "*supported by the text* / *taken from another example of the text* = a value the "
             "thesis states elsewhere; *fitted* = chosen to match the thesis's results; *against "
             "the text* = contradicts a stated value. **Tables**: " + fidelity.get("criteria", "")
             + ". **Figures**: each check tests the quantity the quoted thesis sentence is about "
             "(a position, a trend, a location, a correspondence), measured on our figure's data.")


def known_differences(doc, rows):
    doc.anchor_heading(2, "Known differences", "differences")
    differ = [r for r in rows if category(r["verdict"]) == "differs"]
    if not differ:
        doc.para("None: every comparable item is reproduced.")
        return
    doc.items(f"[{r['item']}](#{r['anchor']}) ({r['example']}): {r['verdict']}. Ours: {r['got']}."
              for r in differ)
    doc.para("The readings of the thesis data behind some of these items (loads, damage data, "
             "norms) are compared in the section on readings.")
