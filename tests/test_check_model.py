"""dd.check_model, a model's self-test: the package's seven models pass it; each planted
mistake (tests/planted_models.py) fails it, with the check that names the mistake."""
import runpy
import shutil
import sys
from pathlib import Path

import pytest

import damage_dolfinx as dd
import planted_models as pm

HERE = Path(__file__).resolve().parent
PACKAGE_MODELS = {"2.1": "2.1-ex1", "2.2": "2.2-ex1", "2.3": "2.3-ex1", "2.4": "2.4-ex1",
                  "3.1": "3.1-ex1", "3.2": "3.2-ex1", "3.3": "3.3-ex1"}


@pytest.mark.parametrize("model", sorted(PACKAGE_MODELS))
def test_the_package_models_pass(model, tmp_path):
    report = dd.check_model(dd.model_class(model), tmp_path, n=5 if model == "2.1" else 2,
                            mpi=False)
    assert report.ok, str(report)
    assert {c.name for c in report.checks if c.status == "pass"} >= {
        "contracts", "prefixes", "stability_limit", "run", "finite", "history_columns",
        "restart"}


def test_an_own_model_passes():
    assert dd.check_model(pm.problem(pm.Compliant), mpi=False).ok


@pytest.mark.parametrize("name", sorted(set(pm.FAILS) - {"rank_dependent"}))
def test_a_planted_mistake_fails_the_check_that_names_it(name):
    report = dd.check_model(pm.problem(pm.PLANTED[name]), mpi=False)
    assert not report.ok
    assert pm.FAILS[name] in report.failed(), str(report)
    failed = report[pm.FAILS[name]]
    assert failed.detail and failed.fix


def test_a_stability_limit_above_the_estimate_fails():
    demo = runpy.run_path(str(HERE.parent / "demos" / "demo_coulomb_friction.py"),
                          run_name="check")
    problem = demo["problem"](4.0, T=0.02)
    assert dd.check_model(problem, mpi=False).ok
    cls = demo["CoulombKelvinVoigt"]
    optimistic = type("optimistic", (cls,), {"id": "kv-coulomb-optimistic",
                                             "mesh_k_max": lambda self: 10 * self._k_max})
    import dataclasses
    report = dd.check_model(dataclasses.replace(problem, model=optimistic), mpi=False)
    assert report.failed() == ["stability_limit"], str(report)


@pytest.mark.mpi
@pytest.mark.skipif(shutil.which("mpirun") is None, reason="no mpirun")
def test_serial_against_two_ranks(tmp_path):
    assert dd.check_model("2.2-ex1", tmp_path / "pkg", n=2)["serial_vs_2_ranks"].status == "pass"
    for name, status in (("Compliant", "pass"), ("rank_dependent", "fail")):
        script = tmp_path / f"{name}.py"
        script.write_text(f"import sys; sys.path.insert(0, {str(HERE)!r}); "
                          "import planted_models as pm; "
                          f"problem = pm.problem(getattr(pm, {name!r}, None) or "
                          f"pm.PLANTED[{name!r}])\n")
        problem = runpy.run_path(str(script))["problem"]
        report = dd.check_model(problem, tmp_path / name, script=script)
        assert report["serial_vs_2_ranks"].status == status, str(report)


@pytest.mark.parametrize("given, message", [
    (dict(steps=0), "steps must be a whole number >= 2, got 0"),
    (dict(steps=2.5), "steps must be a whole number >= 2"),
    (dict(n=-1), "n must be a whole number >= 1, got -1"),
    (dict(mpi="yes"), "mpi must be True or False"),
    (dict(out=__file__), "is a file, not a folder"),
    (dict(script="/nonexistent/model.py"), "is not a file"),
    (dict(name=""), "name must be a non-empty text"),
])
def test_bad_arguments_are_refused_before_any_work(given, message, tmp_path, monkeypatch):
    import damage_dolfinx.api.model_check as mc
    monkeypatch.setattr(mc, "_case_for", lambda model: pytest.fail("work began"))
    with pytest.raises(dd.InputError, match=message):
        dd.check_model(pm.problem(pm.Compliant), **given)


def test_what_to_check_is_named_when_it_is_not_a_model():
    with pytest.raises(dd.InputError, match="check_model takes a Problem, a catalogue case name"):
        dd.check_model(42)


def test_a_model_id_is_its_class():
    from damage_dolfinx.api.model_check import _model_of_id
    assert _model_of_id("3.1") is dd.model_class("3.1")
    assert _model_of_id("3.1-ex1") == "3.1-ex1"


def test_a_folder_of_the_users_in_out_is_refused_untouched(tmp_path):
    mine = tmp_path / "whole"
    mine.mkdir()
    (mine / "notes.txt").write_text("mine")
    with pytest.raises(dd.InputError, match="did not write"):
        dd.check_model(pm.problem(pm.Compliant), out=tmp_path, mpi=False)
    assert (mine / "notes.txt").read_text() == "mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["whole"]
