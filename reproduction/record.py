"""The one record of the report's verdicts: one verdict per item (a thesis table or figure),
from which every place that states it prints it -- the summary row, the figure's caption, the
known differences, the readings section and ``fidelity.md`` -- so that they cannot disagree.

A second, different verdict for an item is refused (:meth:`VerdictRecord.set`). A text written
by hand (``benchmarks/readings.md``) states no verdict of its own: :func:`stated` finds the
verdicts a text states (a bold class word beside an item number), :meth:`VerdictRecord.
disagreements` those that differ from the record, and :meth:`VerdictRecord.fill_readings`
prints the record's verdict beside each row of a hand-written figure table.
"""
from __future__ import annotations

import re

from reproduction.classes import CLASSES, QUICK, category, is_quick

_CLASS = "|".join(re.escape(c) for c in sorted(CLASSES, key=len, reverse=True))
_NUMBERS = r"\d\.\d+(?:\s*(?:/|,|and)\s*\d\.\d+)*"
#: "**2.12/2.13 differs**", "**Figure 2.5 reproduced**" (prose)
_PROSE = re.compile(rf"\*\*(?:(Figures?|Tables?) )?({_NUMBERS})\s+({_CLASS})\b")
#: "**Figure 2.12** (...): ... Verdict: **differs: ...**" (a caption, one line)
_CAPTION = re.compile(rf"\*\*Figure (\d\.\d+)\*\*[^\n]*?Verdict: \*\*({_CLASS})")
#: a table row whose first cell names items: "| [Figure 2.12](#fig-2-12) |", "| 2.12 / 2.13 |"
_ROW_ITEMS = re.compile(rf"^\[?(?:(Figures?|Tables?) )?({_NUMBERS})(?:\]\(#[\w-]+\))?"
                        rf"(?:\s*\([^)]*\))?$")


def _items(kind, numbers, default):
    kind = (kind or default).rstrip("s")
    return [f"{kind} {n}" for n in re.findall(r"\d\.\d+", numbers)]


def stated(text: str, default_kind: str = "Figure") -> list:
    """(item, class) of every verdict ``text`` states: bold class words beside item numbers in
    prose and captions, and table rows whose first cell names items and one of whose cells
    starts with a class (bold or not). ``default_kind``: what a bare number names."""
    out = []
    for line in text.splitlines():
        if line.startswith("|") and not set(line) <= set("|-: "):
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            m = _ROW_ITEMS.match(cells[0]) if cells else None
            if m:
                for cell in cells[1:]:
                    v = re.match(rf"\**({_CLASS})\b", cell)
                    if v:
                        out += [(item, v.group(1))
                                for item in _items(m.group(1), m.group(2), default_kind)]
                        break
            continue
        for m in _PROSE.finditer(line):
            out += [(item, m.group(3)) for item in _items(m.group(1), m.group(2), default_kind)]
        for m in _CAPTION.finditer(line):
            out.append((f"Figure {m.group(1)}", m.group(2)))
    return out


class VerdictRecord:
    """One verdict per item (``"Figure 2.12"``, ``"Table 2.4"``)."""

    def __init__(self):
        self._verdicts = {}

    def set(self, item: str, verdict: str):
        old = self._verdicts.get(item)
        if old is not None and old != verdict:
            raise ValueError(f"{item} has two verdicts: {old!r} and {verdict!r}")
        self._verdicts[item] = verdict

    def __getitem__(self, item: str) -> str:
        return self._verdicts[item]

    def __contains__(self, item) -> bool:
        return item in self._verdicts

    def items(self):
        return self._verdicts.items()

    def disagreements(self, text: str, where: str = "text", default_kind="Figure") -> list:
        """Verdicts ``text`` states that differ from the record's class (empty: they agree)."""
        return [f"{where}: {item} stated as {cls!r}, the record says {category(self[item])!r}"
                for item, cls in stated(text, default_kind)
                if item in self and category(self[item]) != cls]

    def fill_readings(self, text: str) -> str:
        """A hand-written Markdown text with the record's verdict beside every row of its
        figure tables: a column "verdict (this report)" after the last, one class per figure
        the row names, each linked to its summary row."""
        lines, out, in_table, figures = text.splitlines(), [], False, False
        for i, line in enumerate(lines):
            if not line.startswith("|"):
                in_table = False
                out.append(line)
                continue
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if not in_table:  # a header row: a figure table when it names figures first
                in_table = True
                figures = cells[0].lower().startswith("figure")
                out.append(line + (" verdict (this report) |" if figures else ""))
                continue
            if not figures:
                out.append(line)
            elif set(line) <= set("|-: "):
                out.append(line + "---|")
            else:
                m = _ROW_ITEMS.match(cells[0])
                items = _items(m.group(1), m.group(2), "Figure") if m else []
                verdicts = "; ".join(
                    f"[{item}](#fig-{item.split()[1].replace('.', '-')}): "
                    f"**{category(self[item])}**" + (QUICK if is_quick(self[item]) else "")
                    for item in items if item in self)
                out.append(line + f" {verdicts or '-'} |")
        return "\n".join(out) + ("\n" if text.endswith("\n") else "")
