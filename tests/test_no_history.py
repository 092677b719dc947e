"""The repository speaks of itself, not of how it was made: no tracked text file (code, docs,
records) and no tracked file name cites a work item ("issue" followed by a number), a working
session ("this session", "the sixth session", "session 9"), or an absolute path of the machine
it was developed on (the temporary folder, a home folder, the checkout's parent). The history
is in git."""
import re
import shutil
import subprocess

import pytest
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

ORDINAL = ("this|that|next|previous|earlier|later|last|same|one|each|first|second|third|fourth|"
           "fifth|sixth|seventh|eighth|ninth|tenth")
PATTERNS = {
    "work item": re.compile(r"(?<![a-z])issues?[ _#-]*\d+", re.I),
    "working session": re.compile(rf"\b(?:{ORDINAL})(?:\s+and\s+\w+)?\s+sessions?\b|"
                                  r"\bsessions?[ _-]*\d+", re.I),
    "machine path": re.compile(r"(?<![\w.~-])/(?:work|tmp|root|home)/"),
}
#: files that must contain the patterns to test for them: this test, and the report's own check
#: that its generated folder names no machine path or tracker history
ALLOWED = {"tests/test_no_history.py", "tests/test_report.py", "tests/test_no_outside_refs.py"}


def offences(text: str) -> list:
    """(kind, line number, line) of every match in text."""
    found = []
    for number, line in enumerate(text.splitlines(), 1):
        for kind, pattern in PATTERNS.items():
            if pattern.search(line):
                found.append((kind, number, line.strip()[:160]))
    return found


def tracked_text_files(repo=REPO):
    names = subprocess.run(["git", "-C", str(repo), "ls-files", "-z"], capture_output=True,
                           check=True).stdout.decode().split("\0")
    for name in filter(None, names):
        path = repo / name
        if not path.is_file():
            continue
        data = path.read_bytes()
        if b"\0" in data[:8192]:
            continue  # binary: PNG, NPZ, HDF5
        try:
            yield name, data.decode("utf-8")
        except UnicodeDecodeError:
            continue


def scan(repo=REPO) -> list:
    bad = []
    for name, text in tracked_text_files(repo):
        bad += [(name, 0, kind, name) for kind, p in PATTERNS.items() if p.search(name)]
        if name not in ALLOWED:
            bad += [(name, number, kind, line) for kind, number, line in offences(text)]
    return bad


def test_patterns_catch_history():
    assert offences("the 3-D extension (issue 17)")[0][0] == "work item"
    assert offences("records in reference_output/convergence_issue18/")[0][0] == "work item"
    assert offences("measured in the sixth session")[0][0] == "working session"
    assert offences("the fifth and sixth sessions")[0][0] == "working session"
    assert offences("python /work/main/benchmarks/x.py")[0][0] == "machine path"
    assert offences("flock /tmp/team/heavy.lock")[0][0] == "machine path"
    # legitimate uses
    assert not offences("subprocess.Popen(cmd, start_new_session=True); gmsh_session()")
    assert not offences("signal the whole session (mpirun and its ranks); /usr/bin/time -v")
    assert not offences("results/issue_completed; an issue of the reader; ../tmp/x")


@pytest.mark.skipif(shutil.which("git") is None or not (REPO / ".git").exists(),
                    reason="needs git and the repository (the tracked files); the Debian 12 leg "
                           "of CI runs it")
def test_no_history_in_tracked_text():
    bad = scan()
    assert not bad, "\n".join(f"{n}:{line}: {kind}: {text}" for n, line, kind, text in bad[:60])
