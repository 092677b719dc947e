"""Two reports side by side: the count of each verdict class before and after, and every item
whose verdict changed (its class, and its verdict text when only the text changed).

    python benchmarks/reproduction/report_diff.py BEFORE/report/REPORT.md AFTER/report/REPORT.md
        [--out diff.md] [--json diff.json]

Each report's verdicts are read from its summary table (one row per thesis table and figure:
``| item | example | thesis | ours | verdict |``), the one place every other place of the
report prints from.
"""
import argparse
import json
import re
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # benchmarks/: common.py
import common  # noqa: E402,F401  (puts the checkout on sys.path)
from reproduction.classes import CLASSES, category, is_quick  # noqa: E402

_ROW = re.compile(r"^\| \[(?P<item>(?:Table|Figure) \d\.\d+)\]\(#[^)]+\) \| (?P<rest>.*) \|$")


def _cells(rest: str) -> list:
    """The cells of a Markdown table row (escaped bars ``\\|`` kept inside their cell)."""
    return [c.strip().replace("\\|", "|") for c in re.split(r"(?<!\\)\|", rest)]


def summary(text: str) -> dict:
    """{item: (example, ours, verdict)} from a REPORT.md's summary table."""
    out = {}
    for line in text.splitlines():
        m = _ROW.match(line)
        if m:
            cells = _cells(m.group("rest"))
            if len(cells) >= 4:
                out[m.group("item")] = (cells[0], cells[2], cells[-1])
    if not out:
        raise ValueError("no summary table found (rows '| [Figure 2.4](#fig-2-4) | ... |')")
    return out


def counts(rows: dict) -> dict:
    verdicts = [v for _, _, v in rows.values()]
    out = {c: sum(category(v) == c for v in verdicts) for c in CLASSES}
    out["quick"] = sum(is_quick(v) for v in verdicts)
    return out


def compare(before: dict, after: dict) -> dict:
    cb, ca = counts(before), counts(after)
    changed = []
    for item in sorted(set(before) | set(after), key=_order):
        b, a = before.get(item), after.get(item)
        if b is None or a is None or b[2] != a[2]:
            changed.append(dict(
                item=item, example=(a or b)[0],
                before=category(b[2]) if b else "(absent)",
                after=category(a[2]) if a else "(absent)",
                before_verdict=b[2] if b else "", after_verdict=a[2] if a else ""))
    return dict(counts_before=cb, counts_after=ca, total_before=len(before),
                total_after=len(after), changed=changed)


def _order(item):
    kind, number = item.split()
    major, minor = number.split(".")
    return int(major), int(minor), kind


def markdown(d: dict) -> str:
    lines = ["| class | before | after |", "|---|---:|---:|"]
    for c in CLASSES + ("quick",):
        lines.append(f"| {c} | {d['counts_before'][c]} | {d['counts_after'][c]} |")
    lines.append(f"| **items** | {d['total_before']} | {d['total_after']} |")
    lines += ["", f"{sum(r['before'] != r['after'] for r in d['changed'])} items changed class, "
              f"{sum(r['before'] == r['after'] for r in d['changed'])} changed only their "
              "verdict text.", "", "| item | example | before | after |", "|---|---|---|---|"]
    for r in d["changed"]:
        lines.append(f"| {r['item']} | {r['example']} | {r['before']} | {r['after']} |")
    lines.append("")
    for r in d["changed"]:
        lines += [f"### {r['item']} ({r['example']}): {r['before']} -> {r['after']}", "",
                  f"- before: {r['before_verdict'] or '(absent)'}",
                  f"- after: {r['after_verdict'] or '(absent)'}", ""]
    return "\n".join(lines)


if __name__ == "__main__":
    p = argparse.ArgumentParser()
    p.add_argument("before", type=Path)
    p.add_argument("after", type=Path)
    p.add_argument("--out", type=Path)
    p.add_argument("--json", type=Path)
    a = p.parse_args()
    for given in (a.before, a.after):
        if not given.is_file():
            p.error(f"{str(given)!r} is not a file (give two REPORT.md files)")
    d = compare(summary(a.before.read_text()), summary(a.after.read_text()))
    text = markdown(d)
    if a.out:
        a.out.write_text(text + "\n")
    if a.json:
        a.json.write_text(json.dumps(d, indent=1) + "\n")
    print(text)
