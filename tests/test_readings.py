"""Readings of the thesis data: literal = stated data, evidence = documented departures.

Catalogue-level checks (no solve): every departure is an R-entry of the assumptions with thesis
line numbers, the literal reading is the catalogue entry itself, and the reading is selectable
from the command line and through --set reading=..., with bad names refused (exit 2).
"""
import re

import pytest

from damage_dolfinx import cli
from damage_dolfinx.catalogue import examples


def test_literal_is_the_stated_data_and_evidence_departs_with_reasons():
    for ex_id, ex in examples.catalogue().items():
        literal = examples.get(ex_id, "literal")
        evidence = examples.get(ex_id, "evidence")
        assert literal.reading == "literal" and evidence.reading == "evidence"
        assert not any(a.startswith("R") for a in literal.assumptions), ex_id
        departures = [a for a in evidence.assumptions if re.match(r"R\d+ ", a)]
        if ex.readings.get("evidence") is None:
            assert evidence.params == literal.params and not departures, ex_id
            continue
        assert departures, ex_id
        for entry in departures:
            assert re.search(r"line[s]? \d{3,4}", entry), entry  # thesis lines cited
        assert ex.reading == ex.default_reading


def test_reading_changes_only_what_it_lists():
    for ex_id, ex in examples.catalogue().items():
        reading = ex.readings.get("evidence")
        if reading is None:
            continue
        lit, ev = ex.with_reading("literal"), ex.with_reading("evidence")
        changed = {k for k, v in ev.params.as_dict().items() if lit.params.as_dict()[k] != v}
        assert changed == set(reading.overrides), ex_id
        assert (ev.traction is lit.traction) == (reading.traction is None), ex_id
        assert (ev.body_force is lit.body_force) == (reading.body_force is None), ex_id


def test_reading_through_overrides_is_the_same_as_get():
    ex = examples.catalogue()["2.2-ex2"]
    params = ex.configure(overrides={"reading": "literal", "kappa": "0.5"}).params
    assert params.kappa == 0.5
    assert examples.get("2.2-ex2", "literal").traction is not examples.get("2.2-ex2").traction


@pytest.mark.parametrize("args", [["run", "2.2-ex2", "--set", "reading=bogus"],
                                  ["converge", "2.2-ex2", "--set", "reading=bogus"]])
def test_unknown_reading_is_refused(tmp_path, capsys, args):
    assert cli.main(args + ["--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "unknown reading 'bogus'" in err and err.count("\n") == 1


def test_committed_studies_follow_the_default_readings():
    """reference_output/convergence holds each example's thesis-size study in its default
    reading, convergence-literal the literal one of exactly the examples whose default differs
    (readings_ratios.py --summary and fidelity.py read them as such)."""
    import json
    from pathlib import Path
    ref = Path(__file__).resolve().parents[1] / "benchmarks" / "reference_output"
    catalogue = examples.catalogue()
    evidence_default = {i for i, ex in catalogue.items()
                        if ex.default_reading == "evidence" and ex.convergence}
    literal_copies = set()
    for sub in ("convergence", "convergence-literal"):
        for summary in sorted((ref / sub).glob("*/summary.json")):
            if summary.parent.name.endswith("-reduced"):
                continue  # an older reduced-size study kept for comparison
            s = json.loads(summary.read_text())
            reading = s.get("reading") or "literal"
            expected = catalogue[s["example"]].default_reading if sub == "convergence" else "literal"
            assert reading == expected, summary
            if sub == "convergence-literal":
                literal_copies.add(s["example"])
    assert literal_copies == evidence_default


def test_a_run_records_its_assumptions_in_words():
    """summary.json's assumptions and reading record carry no short label of the catalogue's:
    a labelled entry reads ``assumed: ...``; the raw entry keeps its labels (the report reads
    the assumed layouts from them)."""
    import json

    from damage_dolfinx.core import departures
    from damage_dolfinx.problem.example import in_words
    label = re.compile(r"\bG\d+[a-z]?\b")
    assert in_words("1.9/G37: von Mises (G41: unit labels) (G3)") == \
        "assumed: von Mises (assumed: unit labels) (assumed)"
    for reading in ("literal", "evidence"):
        for ex_id, ex in examples.catalogue(reading).items():
            recorded = json.dumps([ex.assumptions, departures.record(ex)])
            assert not label.search(recorded), (ex_id, label.search(recorded).group(0))
    assert any(label.match(a) for a in examples.get("2.1-ex1").literal.assumptions)
