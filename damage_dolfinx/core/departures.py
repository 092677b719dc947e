"""The reading of a run and every departure from the thesis's stated data, as one record that
the run writes into its ``summary.json`` (key ``reading``).

A catalogue example departs from the stated text in two ways, both written among its
``assumptions``:

* a **reading** (``--reading evidence``) replaces some stated values; each replaced value is an
  entry ``R<n> (evidence reading; <basis>): <what> ...``;
* the **data** of every reading may contain a value that contradicts a stated one (a different
  time step, a truncation the text does not use, a stiffness read against the formula, a load
  rate fitted to a result); each such value is an entry ``departure (<basis>): <what> ...``.

``basis`` says whether the text supports the departure or it was fitted (chosen to match the
thesis's results) or goes against the text. A value the thesis does not give at all is an
*assumption*, not a departure, and is not listed here.

The record::

    {"name": "evidence", "default": true,
     "departures": [{"what": "kappa = 0.003 instead of kappa = 1", "basis": "fitted",
                     "fitted": true, "against_text": false, "source": "reading",
                     "text": "<the whole entry>"}, ...]}

An own problem (not from the catalogue) has ``name`` None and no departures.
"""
from __future__ import annotations

import re

_READING = re.compile(r"R\d+ \(evidence (?:reading|candidate)(?:; ([^)]*))?\):\s*(.*)", re.S)
_DATA = re.compile(r"departure \(([^)]*)\):\s*(.*)", re.S)


def _short(text: str) -> str:
    """The departure itself: the entry's first clause (before the thesis reference, the
    evidence or the reasons)."""
    what = re.split(r" \([^()]*\blines? \d|\. |; |: |, the ", text, maxsplit=1)[0]
    depth, cut = 0, len(what)
    for i, ch in enumerate(what):  # an unclosed bracket: cut before it
        if ch in "({":
            depth, cut = depth + 1, (i if depth == 0 else cut)
        elif ch in ")}":
            depth, cut = depth - 1, (len(what) if depth == 1 else cut)
    return what[:cut].strip()[:160]


def _basis(kind: str) -> str:
    kind = (kind or "not stated in the text").strip()
    return "fitted" if kind.upper().startswith("FITTED") else kind


def parse(assumption: str):
    """The departure an assumption entry states (a dict as in the record), or None."""
    for pattern, source in ((_READING, "reading"), (_DATA, "data")):
        m = pattern.match(assumption)
        if m:
            basis = _basis(m.group(1))
            return {"what": _short(m.group(2)), "basis": basis,
                    "fitted": "fitted" in basis.lower() or "chosen to match" in basis,
                    "against_text": "against the text" in basis, "source": source,
                    "text": assumption}
    return None


def departures(assumptions) -> list:
    """Every departure from the stated data among ``assumptions``, in their order."""
    return [d for d in (parse(a) for a in assumptions or ()) if d]


def record(ex) -> dict:
    """The ``reading`` record of a run of example ``ex`` (written into summary.json)."""
    if getattr(ex, "own", False):
        return {"name": None, "default": None, "departures": []}
    base = getattr(ex, "literal", None) or ex
    name = getattr(ex, "reading", None) or getattr(base, "default_reading", "literal")
    return {"name": name, "default": name == getattr(base, "default_reading", "literal"),
            "departures": departures(ex.assumptions)}
