"""The verdict classes of the report and the summary rows (one per thesis table and figure).

Classes, from the strongest claim to none:

* **reproduced**: the stated thesis data give the same content (every check on the quoted
  statement holds; a table within a factor 2 at the thesis's rate);
* **reproduced under a reading**: the same, but only on data that depart from the stated ones;
  each departure is named, with whether the text supports it or it was fitted;
* **setting assumed**: a setting figure whose geometry or boundary layout the thesis does not
  give (drawn from our assumption);
* **not visible in this figure**: the data carry the statement but the thesis-style figure
  cannot show it (the damage is one colour on the fixed [zeta*, 1] scale, or has not developed):
  the verdict says what the data show, and the figure adds a panel on the field's own range;
* **differs**: a check fails, or the table's errors or rate do not match (how is said);
* **not comparable**: nothing measurable, or a thesis table this report does not set beside
  ours.
"""
from __future__ import annotations

import html
import re

from reproduction.doc import _inline

CLASSES = ("reproduced", "reproduced under a reading", "setting assumed",
           "not visible in this figure", "differs", "not comparable")
CSS = {"reproduced": "v-reproduced", "reproduced under a reading": "v-reading",
       "setting assumed": "v-assumed", "not visible in this figure": "v-invisible",
       "differs": "v-differs", "not comparable": "v-not"}


def category(verdict: str) -> str:
    """The class a verdict text starts with (the longest match)."""
    for c in sorted(CLASSES, key=len, reverse=True):
        if verdict.startswith(c):
            return c
    return "not comparable"


def headline(counts: dict) -> str:
    return ", ".join(f"{counts[c]} {c}" for c in CLASSES)


def table_verdict(t: dict) -> str:
    """A thesis error table beside our study (benchmarks/reproduction/fidelity.py's comparison)."""
    from reproduction.checks import departure
    v = t.get("verdict", "not comparable")
    if v.startswith("not comparable"):
        return v
    if not v.startswith("reproduced"):
        how = {"magnitude": "errors within 2x, but the rates differ"}.get(v.split()[0], v)
        how = re.sub(r"^(rate only|differs) \((.*)\)$", r"\2", how)
        return f"differs: {how} (median ratio {t['ratio_median']:.2g}, rate " \
               f"{t['rate_ours']:.2f} against {t['rate_thesis_common_cells']:.2f})"
    if not t.get("departures"):
        return "reproduced"
    text = "reproduced under a reading: " + "; ".join(departure(d) for d in t["departures"])
    lit = t.get("literal")
    if lit:
        text += (f". The stated data give {lit['ratio_min']:.2g}-{lit['ratio_max']:.2g}x the "
                 f"thesis's errors (median {lit['ratio_median']:.2g}), rate {lit['rate_ours']:.2f} "
                 f"against {lit['rate_thesis_common_cells']:.2f}")
    return text


def table_rows(fidelity, results, study_folder, load_json, sort_key):
    rows = []
    for t in fidelity["tables"]:
        got = (f"median ratio ours/thesis {t['ratio_median']:.3g} (min {t['ratio_min']:.3g}, max "
               f"{t['ratio_max']:.3g}) over {t['n_common']} cells; rate {t['rate_ours']:.2f} vs "
               f"{t['rate_thesis_common_cells']:.2f}" if "ratio_median" in t else "no study")
        rows.append(dict(key=sort_key(t["table"], 0), item=f"Table {t['table']}",
                         anchor=f"table-{t['table'].replace('.', '-')}", example=t.get("study", ""),
                         shows=f"errors of {t['example']} ({t.get('thesis_norm', '')})", got=got,
                         verdict=table_verdict(t)))
    for number, study in (("2.1", "2.1-ex1"), ("3.3", "3.3-ex1")):
        folder = study_folder(results, study)
        rate = ((load_json(folder / "summary.json") or {}).get("rates", {}).get("h_plus_k_all")
                if folder else None)
        rows.append(dict(key=sort_key(number, 0), item=f"Table {number}", anchor=f"study-{study}",
                         example=study, shows="errors against h + k",
                         got=f"our study: rate {rate:.2f} in h + k" if rate else "no study",
                         verdict="not comparable: this report does not set the thesis's table "
                                 "beside our study (our errors and rate are shown alone)"))
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
        f"| [{r['item']}](#{r['anchor']}) | {r['example']} | {r['shows']} | {r['got']} | "
        f"{r['verdict']} |\n" for r in rows)
    doc.raw('<table class="summary"><tr><th class="l">item</th><th class="l">example</th>'
            '<th class="l">what the thesis shows</th><th class="l">what we get</th>'
            f'<th class="l">verdict</th></tr>{body}</table>', md)
    doc.note("**Classes.** *reproduced*: the stated data give the same content. *reproduced "
             "under a reading*: the same, on data that depart from the stated ones (each "
             "departure named; *fitted* = chosen to match the thesis's results, *taken from the "
             "text* = a value the thesis states elsewhere). *setting assumed*: the thesis does not "
             "give this geometry or boundary layout; ours is an assumption. *not visible in this "
             "figure*: the data carry the statement, but on the thesis's fixed damage scale "
             "[ζ*, 1] the field is one colour (or no damage developed); the verdict says what the "
             "data show and the figure adds a panel on the field's own range. *differs*: how is "
             "said. *not comparable*: nothing measurable. **Tables**: "
             + fidelity.get("criteria", "") + ". **Figures**: each check tests the quantity the "
             "quoted thesis sentence is about (a position, a trend, a location, a "
             "correspondence), measured on our figure's data.")


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
