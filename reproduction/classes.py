"""The verdict classes of the report: one rule per class, applied by :func:`classify` to what
an item's data show (:class:`Evidence`). The report's summary, its captions and
``fidelity.md`` all print the text :func:`classify` returns, so they cannot disagree.

The rules, in the order they are applied (the first that applies gives the class):

1. **not comparable**, when the item was not produced; when the thesis states nothing about
   it that could be tested (a figure that only shows what is plotted, a withheld table; refused
   when the item quotes a thesis statement: that statement is tested); when
   its run stops before the time the thesis's statement is about (an early stop is never
   evidence); or when nothing the statement names could be measured. A check that holds by
   construction (``Evidence.sanity``: the damage plotted within [ζ*, 1], which the solver
   enforces) is no measurement of the statement: it can make a verdict differ, never carry one.
2. **drawn as stated**: a setting figure that draws the geometry and boundary layout the thesis
   states. It is a drawing, not a result.
3. **setting assumed**: a setting figure whose geometry or layout the thesis does not give (or
   gives inconsistently); ours is an assumption, named.
4. **differs**: a check of the quantity the thesis sentence names fails. The verdict names the
   quantity and quotes our number. A drawing that is hard to read is not a failed check. A
   check counts only when its premise holds (contact exists where penetration is judged; the
   damage is away from ζ* where its pattern is judged); where the premise fails, the check
   fails with that reason. Each statement is tagged with its subject (damage, stress,
   configuration, contact, a number) and is judged only by the checks of that subject.
   Where no check fails but a check of the statement could not be measured, the item is
   **not comparable** (the part measured is not the statement).
5. **not visible in this figure**: every check holds (the data carry the statement), but the
   figure cannot show it: the damage field spans less than ``ONE_COLOUR`` of the fixed colour
   scale [ζ*, 1], or two fields that should differ are the same colours (statements about the
   damage only).
6. **reproduced under a reading**: every check holds, on data that depart from the stated
   text. Each departure is named with its basis (supported by the text, taken from another
   place of the text, fitted to the thesis's results, or against the text).
7. **reproduced**: every check holds, on the stated data, to the thesis's time.

Every verdict of classes 4-7 lists the departures of its data. A verdict judged on a quick
(coarse) run ends with ``(quick)``; the headline counts them.
"""
from __future__ import annotations

from dataclasses import dataclass, field

CLASSES = ("reproduced", "reproduced under a reading", "drawn as stated", "setting assumed",
           "not visible in this figure", "differs", "not comparable")

#: the rule of each class in one sentence (the report prints these under its summary)
RULES = {
    "reproduced": "every check of the quantity the thesis names holds, on the stated data, to "
                  "the thesis's time (tables: median ratio ours/thesis in [0.5, 2] and rates "
                  "within 0.25)",
    "reproduced under a reading": "the same, on data that depart from the stated text; each "
                                  "departure is named with its basis",
    "drawn as stated": "a setting figure drawing the geometry the thesis states: a drawing, "
                       "not a result",
    "setting assumed": "a setting figure whose geometry or layout the thesis does not give; "
                       "ours is an assumption",
    "not visible in this figure": "the data carry the statement (every check holds) but the "
                                  "figure cannot show it (a statement about the damage: a "
                                  "damage range under 5 % of the fixed scale, or two fields in "
                                  "the same colours)",
    "differs": "a check of the quantity the thesis sentence names fails (the checks of the "
               "statement's subject only), or its premise fails (no contact where penetration "
               "is judged, damage at ζ* nearly everywhere where a pattern is judged); the "
               "number is quoted",
    "not comparable": "nothing to test: not produced, no statement of its own in the thesis, a "
                      "withheld table, nothing measured (a check that holds by construction, "
                      "such as the damage within [ζ*, 1], measures nothing), part of the "
                      "statement not measured and nothing failed, or a run that stops before "
                      "the thesis's time (never evidence)",
}

#: a damage field spanning less than this fraction of the fixed scale [zeta*, 1] is one colour
#: (the figures add a panel on the field's own range below the same fraction)
from damage_dolfinx.viz.figscales import NARROW_DAMAGE as ONE_COLOUR  # noqa: E402

#: the suffix of a verdict judged on a quick (coarse) run
QUICK = " (quick)"

#: what each class says an item rests on (the headline)
RESTS_ON = {"reproduced": "a result", "reproduced under a reading": "a reading",
            "drawn as stated": "a drawing of the stated geometry"}


@dataclass
class Evidence:
    """What an item's data show, for :func:`classify`.

    ``checks``: (what is tested, holds: True/False/None if not measured, our number as text).
    ``sanity``: checks of the same form that hold by construction (the damage plotted within
    [ζ*, 1]): a failed one makes the verdict differ, but they never carry a verdict.
    ``departures``: the departure records of the data (summary.json's ``reading``).
    """
    kind: str = "result"                 # result | table | setting
    missing: str = ""                    # why the item was not produced ('' if it was)
    statement: bool = True               # the thesis states something testable about it
    no_statement: str = ""               # why not (for the verdict)
    quote: str = ""                      # the thesis sentence the row quotes ('' if none)
    checks: list = field(default_factory=list)
    sanity: list = field(default_factory=list)
    departures: list = field(default_factory=list)
    stopped_early: str = ""              # the run stops before the thesis's time: how
    invisible: str = ""                  # why the figure cannot show what the data carry
    layout_assumed: str = ""             # the assumed geometry or layout of a setting figure
    quick: bool = False


def departure_text(d) -> str:
    """'kappa = 0.003 instead of kappa = 1 (fitted)' from a departure record (or a string)."""
    if isinstance(d, str):
        return d
    return f"{d['what']} ({d['basis']})"


def departures_text(departures) -> str:
    return "; ".join(departure_text(d) for d in departures)


def classify(e: Evidence) -> str:
    """The verdict of an item: its class first, then what it rests on (RULES, in order)."""
    return _classify(e) + (QUICK if e.quick else "")


def _classify(e: Evidence) -> str:
    if e.missing:
        return f"not comparable: {e.missing}"
    if e.kind == "setting":
        if e.layout_assumed:
            return f"setting assumed: {e.layout_assumed}"
        return "drawn as stated: a drawing of the geometry and layout the text states, not a result"
    if not e.statement:
        if e.quote:  # the row quotes the very sentence a "nothing to test" would deny
            raise ValueError(f"a 'nothing to test' verdict beside a quoted statement is refused: "
                             f"test “{e.quote[:60]}...” or quote nothing")
        return f"not comparable: {e.no_statement or 'the thesis states nothing to test here'}"
    if e.stopped_early:
        return f"not comparable: {e.stopped_early}; a run that stops early is no evidence"
    measured = [c for c in e.checks if c[1] is not None]
    if not measured:
        return "not comparable: nothing the thesis's statement names is measured" + (
            " (only what holds by construction: " + "; ".join(c[0] for c in e.sanity) + ")"
            if e.sanity else "")
    sanity = [c for c in e.sanity if c[1] is not None]
    tail = f"; departures: {departures_text(e.departures)}" if e.departures else ""
    failed = [c for c in sanity + measured if not c[1]]
    if failed:
        return "differs: " + "; ".join(f"the thesis says: {c[0]}; ours: {c[2]}" if c[2] else
                                       f"the thesis says: {c[0]}; ours: it does not hold"
                                       for c in failed) + tail
    held = "; ".join(f"{c[0]} ({c[2]})" if c[2] else c[0] for c in sanity + measured)
    unmeasured = [c[0] for c in e.checks if c[1] is None]
    if unmeasured:
        return (f"not comparable: part of the statement is not measured ({'; '.join(unmeasured)})"
                f"; what is measured holds: {held}{tail}")
    if e.invisible:
        return f"not visible in this figure: {e.invisible}; the data show: {held}{tail}"
    if e.departures:
        return f"reproduced under a reading: {departures_text(e.departures)}; the data show: {held}"
    return f"reproduced: {held}"


def category(verdict: str) -> str:
    """The class a verdict text starts with (the longest match)."""
    for c in sorted(CLASSES, key=len, reverse=True):
        if verdict.startswith(c):
            return c
    return "not comparable"


def is_quick(verdict: str) -> bool:
    return verdict.endswith(QUICK)


def counts(verdicts) -> dict:
    """{class: count} plus 'quick': how many verdicts rest on quick runs."""
    verdicts = list(verdicts)
    out = {c: sum(category(v) == c for v in verdicts) for c in CLASSES}
    out["quick"] = sum(is_quick(v) for v in verdicts)
    return out


def headline(c: dict) -> str:
    """What the verdicts rest on, in one sentence."""
    total = sum(c[k] for k in CLASSES)
    text = (f"of {total} thesis tables and figures, {c['reproduced']} reproduce a result on the "
            f"stated data, {c['reproduced under a reading']} reproduce it only under a reading "
            f"(departures named), {c['drawn as stated']} are only a drawing of the stated "
            f"geometry and {c['setting assumed']} a drawing of an assumed one; "
            f"{c['not visible in this figure']} not visible in the figure, {c['differs']} "
            f"differ, {c['not comparable']} not comparable")
    if c.get("quick"):
        text += f"; {c['quick']} verdicts are judged on quick (coarse) runs"
    return text


def record_departures(summary: dict, catalogue=None) -> list:
    """The departure records of a run or study: its summary's ``reading`` record; for a
    summary written before runs recorded it, the catalogue's record of its example under the
    reading its assumptions name."""
    from damage_dolfinx.core import departures
    from damage_dolfinx.catalogue import examples
    reading = summary.get("reading")
    if isinstance(reading, dict):  # the short form from the recorded entry, as parsed today
        return [departures.parse(d["text"]) or d if d.get("text") else d
                for d in reading.get("departures", [])]
    name = reading if isinstance(reading, str) else None
    for a in summary.get("assumptions", []):
        if name is None and a.startswith("reading: "):
            name = a.split()[1]
    example = summary.get("example", "")
    try:
        ex = (catalogue or {}).get(example) or examples.get(example)
        ex = (ex.literal or ex).with_reading(name or "literal")
    except Exception:  # an example no longer in the catalogue: what its summary says
        return departures.departures(summary.get("assumptions", []))
    return departures.record(ex)["departures"]
