"""The benchmark scripts stay runnable after the layout of benchmarks/ by purpose: each one
imports and answers --help, and the numbers readings.md quotes are readings_ratios.py's output
from the committed records."""
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
BENCH = REPO / "benchmarks"
SCRIPTS = sorted(p for p in BENCH.glob("*/*.py"))


def test_every_script_has_a_purpose_folder():
    """No script at the top of benchmarks/ besides the shared helpers."""
    assert sorted(p.name for p in BENCH.glob("*.py")) == ["common.py"]
    assert {p.parent.name for p in SCRIPTS} == {"faults", "performance", "platforms",
                                                 "reproduction", "studies"}


@pytest.mark.parametrize("script", [p.relative_to(BENCH).as_posix() for p in SCRIPTS])
def test_script_imports(script):
    out = subprocess.run([sys.executable, str(BENCH / script), "--help"], cwd=REPO,
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0 and "usage:" in out.stdout, out.stderr[-2000:]


def test_readings_summary_is_the_scripts_output():
    """Every row of the summary table in readings.md is what readings_ratios.py --summary prints
    from the committed studies and benchmarks/thesis_tables.json."""
    out = subprocess.run([sys.executable, str(BENCH / "reproduction" / "readings_ratios.py"),
                          "--summary"], cwd=REPO, capture_output=True, text=True, check=True)
    rows = [line for line in out.stdout.splitlines() if line.startswith("| 2.") or
            line.startswith("| 3.")]
    assert len(rows) == 9
    readings = (BENCH / "readings.md").read_text()
    missing = [row for row in rows if row not in readings]
    assert not missing, missing


def test_readme_tables_come_from_records():
    """Every table of benchmarks/README.md marked <!-- record: PATH --> is copied line for line
    from that record (PATH relative to benchmarks/): no number in it is typed by hand."""
    lines = (BENCH / "README.md").read_text().splitlines()
    marked = 0
    for i, line in enumerate(lines):
        if not line.startswith("<!-- record: "):
            continue
        record = BENCH / line[len("<!-- record: "):].removesuffix(" -->").strip()
        assert record.is_file(), record
        source = set(record.read_text().splitlines())
        table = []
        for row in lines[i + 1:]:
            if not row.startswith("|"):
                break
            table.append(row)
        assert len(table) >= 3, (record, "no table after the marker")
        typed = [row for row in table if row not in source]
        assert not typed, (record, typed)
        marked += 1
    assert marked >= 5
