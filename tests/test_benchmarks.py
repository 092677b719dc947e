"""The benchmark scripts stay runnable after the layout of benchmarks/ by purpose: each one
imports and answers --help, and the numbers readings.md quotes are readings_ratios.py's output
from the committed records."""
import subprocess
import sys
from pathlib import Path

import numpy as np
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


def _scaling_2d():
    import importlib.util
    spec = importlib.util.spec_from_file_location(
        "scaling_2d", BENCH / "performance" / "scaling_2d.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_scaling_2d_report(tmp_path):
    """The 2-D scaling report from one real tiny run and rows derived from it at sizes of the
    fit (time per step = c N^1.1 serially, c N^0.9 on 2 ranks): the tables carry every row, the
    least-squares exponent and the local slopes are the ones put in, a tagged variant is
    compared with its base run (same answers: difference 0); the serial / 2-rank table carries
    the speed-up and efficiency put in, and the README's scaling block (between its markers) is
    rewritten from the records, the text around it kept."""
    import json
    script = BENCH / "performance" / "scaling_2d.py"
    out, record = tmp_path / "out", tmp_path / "record"
    subprocess.run([sys.executable, str(script), "run", "2.1-ex1", "--n", "10", "--steps", "3",
                    "--out", str(out)], cwd=REPO, check=True, capture_output=True, timeout=120)
    runs = out / "runs"
    real = json.loads((runs / "2.1-ex1_n10_p1_auto.json").read_text())
    assert real["dofs_u"] > 0 and len(real["step_times_s"]) == 4
    for example in ("2.1-ex1", "3.1-ex1"):
        for ranks, power in ((1, 1.1), (2, 0.9)):
            for i, dofs in enumerate((10_000, 40_000, 160_000, 640_000)):
                times = [0.1 * (dofs / 1e4) ** power] * 4
                row = {**real, "example": example, "n": 100 * (i + 1), "ranks": ranks,
                       "dofs_u": dofs, "step_times_s": times, "step_s": times[-1],
                       "step_median_s": times[-1]}
                (runs / f"{example}_n{row['n']}_p{ranks}_auto.json").write_text(json.dumps(row))
    (runs / "2.1-ex1_n10_p1_auto_same.json").write_text(json.dumps(
        {**real, "tag": "same", "options": ["-mech_amg_rebuild_its", "0"]}))
    import itertools
    module = _scaling_2d()
    readme = tmp_path / "README.md"
    readme.write_text(f"before\n{module.README_BEGIN}\nold\n{module.README_END}\nafter\n")
    proc = subprocess.run([sys.executable, str(script), "report", "--out", str(out),
                           "--record", str(record), "--readme", str(readme)], cwd=REPO,
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    efficiency = (record / "efficiency.md").read_text().splitlines()
    one, two = 0.1 * 64 ** 1.1, 0.1 * 64 ** 0.9  # 640 000 unknowns, c N^1.1 and c N^0.9
    setup = real["start_s"] + real["first_step_s"]  # the derived rows keep the real run's
    assert (f"| 3.1-ex1 | 400 | 640 000 | {one:.3g} ({one:.3g}-{one:.3g}) | "
            f"{two:.3g} ({two:.3g}-{two:.3g}) | {one / two:.2f} | {one / two / 2:.2f} | "
            f"{setup:.3g} / {setup:.3g} |") in efficiency, efficiency
    text = readme.read_text().splitlines()
    assert text[:2] == ["before", module.README_BEGIN] and text[-2:] == [module.README_END,
                                                                         "after"]
    assert "old" not in text and any("scaling_2d.py run 3.1-ex1 --n $n --ranks 2" in line
                                     for line in text)
    assert any("efficiency.md" in line for line in text)  # the serial / 2-rank table's place
    for marker in ("scaling.md",):  # the exponents copied from their record
        i = next(i for i, line in enumerate(text) if line.startswith("<!-- record: ")
                 and line.endswith(f"{marker} -->"))
        table = list(itertools.takewhile(lambda line: line.startswith("|"), text[i + 1:]))
        source = (record / marker).read_text().splitlines()
        assert len(table) >= 3 and all(line in source for line in table)
    scaling = (record / "scaling.md").read_text()
    rows = [line for line in scaling.splitlines() if line.startswith("| ")]
    assert sum(line.startswith(("| 1 | ", "| 2 | ")) for line in rows) == 17  # 2 x 8 + n = 10
    assert "| 2.1-ex1 | 1 | 4 | 1e+04 - 6.4e+05 | **1.10** | 1.10 | 1.10, 1.10, 1.10 |" in rows
    assert "| 3.1-ex1 | 2 | 4 | 1e+04 - 6.4e+05 | **0.90** | 0.90 | 0.90, 0.90, 0.90 |" in rows
    variants = (record / "variants.md").read_text()
    assert "| 2.1-ex1 | 1 | 10 |" in variants and "1.00 |" in variants
    assert "0.0e+00, 0.0e+00" in variants
    assert (record / "scaling.png").stat().st_size > 0
    rows = [{"dofs_u": d, "step_median_s": 2.0 * d ** 1.25} for d in (5e3, 2e4, 8e4, 3.2e5)]
    assert abs(module.fit(rows) - 1.25) < 1e-12
    assert np.allclose(module.local_slopes(rows), [1.25, 1.25])
