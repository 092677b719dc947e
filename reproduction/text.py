"""The report's text as a reader outside the project reads it (report.py applies these to every
block): thesis references by section and page instead of line numbers of a plain-text copy,
the catalogue's internal assumption codes replaced by what they mean, development history and
machine paths left out.

* ``thesis line 3973`` / ``lines 1093-1095`` -> ``§3.2.3, p. 176``: the thesis's own section
  and page (its table of contents), found from the line the catalogue cites;
* ``G6: kappa = 1e-2 ...`` -> ``assumed: kappa = 1e-2 ...`` (a value the thesis does not
  give); ``R1 (evidence reading; FITTED value): ...`` -> ``reading (fitted): ...`` (a departure
  from the stated data, fitted to the thesis's results); ``R2 (evidence reading; supported by
  the text): ...`` -> ``reading (supported by the text): ...``; an inline ``(G3)`` ->
  ``(assumed)``;
* references to the project's tracker and working sessions are dropped; absolute paths are
  written relative to the repository or the results folder.
"""
from __future__ import annotations

import re
from pathlib import Path

#: (first line in the plain-text copy the catalogue cites, section, page of the thesis)
SECTIONS = [
    (248, "1", 27), (254, "1.1", 28), (311, "1.2", 31), (407, "1.2.1", 35), (447, "1.3", 37),
    (581, "1.4", 43), (686, "2", 47), (706, "2.1", 49), (806, "2.1.1", 52), (824, "2.1.2", 53),
    (1037, "2.1.3", 60), (1146, "2.2", 68), (1269, "2.2.1", 72), (1301, "2.2.2", 74),
    (1560, "2.2.3", 83), (1666, "2.2.4", 87), (1764, "2.3", 93), (1862, "2.3.1", 96),
    (1976, "2.3.2", 100), (2143, "2.3.3", 106), (2248, "2.4", 113), (2403, "2.4.1", 117),
    (2459, "2.4.2", 119), (2720, "2.4.3", 128), (2808, "3", 135), (2896, "3.1", 139),
    (2974, "3.1.1", 141), (3096, "3.1.2", 145), (3303, "3.1.3", 153), (3409, "3.2", 159),
    (3487, "3.2.1", 161), (3727, "3.2.2", 169), (3950, "3.2.3", 176), (4025, "3.3", 181),
    (4107, "3.3.1", 183), (4237, "3.3.2", 187), (4424, "3.3.3", 194), (4522, "Conclusions", 201),
]

#: the subsection "Numerical examples" of each thesis section
EXAMPLES_SECTION = {"2.1": "2.1.3", "2.2": "2.2.4", "2.3": "2.3.3", "2.4": "2.4.3",
                    "3.1": "3.1.3", "3.2": "3.2.3", "3.3": "3.3.3"}


def section_of_line(line: int) -> tuple:
    """(section, page) of the thesis containing a line of the cited copy."""
    found = SECTIONS[0]
    for entry in SECTIONS:
        if entry[0] <= line:
            found = entry
    return found[1], found[2]


def section_ref(section: str) -> str:
    page = next((p for _, s, p in SECTIONS if s == section), None)
    return f"§{section}" + (f", p. {page}" if page else "")


def example_ref(example_id: str) -> str:
    """'2.1-ex2a' -> '§2.1.3, p. 60, Example 2' (where the thesis presents the example)."""
    m = re.match(r"(\d\.\d)-ex(\d)", example_id)
    if not m:
        return ""
    return f"{section_ref(EXAMPLES_SECTION.get(m.group(1), m.group(1)))}, Example {m.group(2)}"


def _lines_to_sections(m) -> str:
    numbers = [int(x) for x in re.findall(r"\d{3,4}", m.group(0))]
    refs = []
    for n in numbers:
        ref = section_ref(section_of_line(n)[0])
        if ref not in refs:
            refs.append(ref)
    return "thesis " + "; ".join(refs)


#: "thesis line 3973", "lines 1093-1095", "line 1131, 2157", "thesis lines 3958-3963"
_LINES = re.compile(r"(?:thesis(?:\.txt)? )?\blines? \d{3,4}(?:\s*(?:-|–|,|and)\s*\d{3,4})*")

_CODES = [  # (pattern, replacement) for the catalogue's assumption codes
    (re.compile(r"\bR\d+ \(evidence reading; FITTED value\):\s*"), "reading (fitted): "),
    (re.compile(r"\bR\d+ \(evidence reading; ([^)]*)\):\s*"), r"reading (\1): "),
    (re.compile(r"\bR\d+ \(evidence (?:reading|candidate)\):\s*"), "reading: "),
    (re.compile(r"^(?:[\d.]+/)?G\d+[a-z]?(?:/G?\d+[a-z]?)*(?:/[\d.]+)?:\s*"), "assumed: "),
    (re.compile(r"\((?:G\d+[a-z]?)(?:[,/ ]+G\d+[a-z]?)*\)"), "(assumed)"),
    (re.compile(r"\b(?:[\d.]+/)?G\d+[a-z]?(?:/G\d+[a-z]?)*\b"), "assumed"),
    (re.compile(r"\(R\d+(?:, R\d+)*\)"), "(see the readings)"),
    (re.compile(r"\bR-entries\b"), "readings"),
    (re.compile(r"\bPROBLEMS\.md gap numbers?\b"), "assumptions"),
]

_HISTORY = [  # development history a reader has no use for
    (re.compile(r"\s*\((?:GitHub )?issues? \d+[^()]*\)"), ""),
    (re.compile(r"\bissues? \d+(?:/\d+)*(?:, (?:first|second|third|fourth|fifth|sixth|"
                r"seventh)(?: and \w+)? sessions?)?(?: \(beyond the thesis\))?:?\s*"), ""),
    (re.compile(r",?\s*\b(?:this|the (?:first|second|third|fourth|fifth|sixth|seventh)|"
                r"an earlier|one) session\b"), ""),
]

_PATHS = re.compile(r"(?<![\w.])/(?:work|tmp|root|home|var|usr|opt|mnt)(?:/[\w.+@-]+)+")


def assumption(text: str) -> str:
    """A catalogue assumption as the report prints it (codes replaced by their meaning)."""
    for pattern, repl in _CODES:
        text = pattern.sub(repl, text)
    return reader_text(text)


#: codes inside running text (benchmarks/readings.md): "(G6: 1e-2)", "Reading R1 (evidence"
_INLINE_CODES = [(re.compile(r"\b(?:[\d.]+/)?G\d+[a-z]?(?:/G\d+[a-z]?)*:\s*"), "assumed: "),
                 (re.compile(r"\(G\d+[a-z]?\)"), "(assumed)")]


def reader_text(text: str, roots=()) -> str:
    """Thesis line numbers -> sections and pages, no tracker history, no machine paths, no
    internal codes (``roots``: folders whose absolute path is written relative, e.g. the
    results folder)."""
    text = _LINES.sub(_lines_to_sections, text)
    for pattern, repl in _INLINE_CODES:
        text = pattern.sub(repl, text)
    for pattern, repl in _HISTORY:
        text = pattern.sub(repl, text)
    for root, shown in roots:
        text = text.replace(str(root).rstrip("/") + "/", shown + "/" if shown else "")
        text = text.replace(str(root), shown or ".")
    return _PATHS.sub(lambda m: Path(m.group(0)).name, text)


#: words and paths the self-contained report never contains (tests/test_report.py)
FORBIDDEN = [re.compile(p, re.I) for p in (
    r"(?<![\w.])/(?:work|tmp|root|home)/", r"\bissue\s*\d+", r"\bthis session\b",
    r"withheld from us", r"PROBLEMS\.md", r"thesis(?:\.txt)? lines? \d", r"\bG\d+:",
    r"\bR\d+ \(evidence (?:reading|candidate)", r"\.\./", r"(?-i:\bG\d+[a-z]?\b)")]


def forbidden(text: str) -> list:
    """The forbidden words and paths found in ``text`` (empty: the text stands alone)."""
    return [m.group(0) for p in FORBIDDEN for m in p.finditer(text)]


def self_contained_problems(folder) -> list:
    """What keeps a report folder from standing alone: forbidden words and paths in its
    documents, claims of agreement with tables the project has not, and links
    to images that are absolute, leave the folder or are missing."""
    folder = Path(folder)
    problems = []
    for doc in sorted(folder.glob("*.html")) + sorted(folder.glob("*.md")):
        text = doc.read_text()
        problems += [f"{doc.name}: {w!r}" for w in forbidden(text)]
        problems += [f"{doc.name}: claims what the project has not: {c!r}"
                     for c in unsupported_claims(text)]
        links = re.findall(r'<img[^>]* src="([^"]+)"', text) + re.findall(r"!\[[^]]*\]\(([^)]+)\)", text)
        for link in links:
            target = (folder / link).resolve()
            if link.startswith("/") or "://" in link or folder.resolve() not in target.parents \
                    or not target.is_file():
                problems.append(f"{doc.name}: image {link!r} not inside the folder")
    return problems


#: thesis tables this project has no values of (the thesis's copy here lacks them): nothing may
#: claim agreement with them
UNAVAILABLE_TABLES = ("2.1", "3.3")
_UNAVAILABLE = re.compile(r"\bTables?\s+(?:[\d.]+\s*(?:,|and|/|-)\s*)*(?:"
                          + "|".join(re.escape(t) for t in UNAVAILABLE_TABLES)
                          + r")(?![\d.]*\d)")
_AGREEMENT = re.compile(r"(?<![/\w.])(?:agree\w*|match\w*|reproduc\w*|consistent with|in line with|"
                        r"compares? well|confirm\w*|as in|same as|close to)\b(?![/.]\w)", re.I)
_NEGATED = re.compile(r"\b(?:not|never|no|cannot|nor|without)\b", re.I)
#: the agreement word and the table within this many characters of each other
_NEAR = 60


def unsupported_claims(text: str) -> list:
    """Passages of ``text`` that claim agreement with a thesis table the project cannot
    compute against (UNAVAILABLE_TABLES): an agreement word and the table within _NEAR
    characters, with no negation between them or just before the agreement word. Python's
    implicit string concatenation across lines is joined first."""
    text = re.sub(r"\"\s*\n\s*[fr]?\"", "", text)   # a string literal continued on the next line
    text = re.sub(r"\s+", " ", text)
    out = []
    for table in _UNAVAILABLE.finditer(text):
        lo, hi = max(0, table.start() - _NEAR), table.end() + _NEAR
        for word in _AGREEMENT.finditer(text, lo, hi):
            between = text[min(word.end(), table.start()):max(word.start(), table.end())]
            before = text[max(0, word.start() - 30):word.start()]
            if not _NEGATED.search(between) and not _NEGATED.search(before):
                out.append(text[lo:hi].strip())
                break
    return out
