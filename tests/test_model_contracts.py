"""A model's declarations are checked against what it builds (models/contracts.py), and the
state check after every step covers every Function it holds as state: each planted mistake of
tests/planted_models.py is refused before any step, or stops the run as failed, with a message
naming what to fix; the correct model runs."""
import json

import numpy as np
import pytest

import damage_dolfinx as dd
import planted_models as pm
from damage_dolfinx.models.contracts import ContractError


def run(cls, out, **kw):
    return dd.run(pm.problem(cls, **kw.pop("problem", {})), str(out), progress=False,
                  figures=False, **kw)


def test_the_correct_model_runs(tmp_path):
    assert run(pm.Compliant, tmp_path / "ok")["status"] == "completed"


def test_a_nan_in_a_field_of_its_own_fails_the_run(tmp_path):
    with pytest.raises(dd.ConvergenceError, match="theta is not finite"):
        run(pm.PLANTED["nan_in_own_field"], tmp_path / "nan")
    assert json.loads((tmp_path / "nan" / "summary.json").read_text())["status"] == "failed"


def test_what_the_step_starts_from_is_checkpointed_by_construction(tmp_path):
    cls = pm.PLANTED["field_not_checkpointed"]
    whole = run(cls, tmp_path / "whole")
    run(cls, tmp_path / "half", problem=dict(T=0.1), checkpoint_every=1)
    resumed = run(cls, tmp_path / "half", restart=True)
    assert whole["status"] == resumed["status"] == "completed"
    a, b = (np.load(tmp_path / f / "fields_final.npz") for f in ("whole", "half"))
    assert np.array_equal(a["theta"], b["theta"]) and np.array_equal(a["zeta"], b["zeta"])


@pytest.mark.parametrize("name, message", [
    ("override_drops_field", "starts from 'theta' of the previous step"),
    ("old_state_without_zeta", r"add \('zeta', 'zeta_old'\) to old_state"),
    ("old_state_without_u", r"add \('u', 'u_old'\) to old_state"),
    ("wrong_prefix", "declares the PETSc prefix 'velocity_', but its solver uses 'mech_'"),
    ("update_names_nothing", "update names 'w'"),
    ("unknown_norm", "'u' has the norm 'H1'; the norms are V, L2, L2_GammaC"),
])
def test_a_broken_declaration_is_refused_before_any_step(tmp_path, name, message):
    with pytest.raises(ContractError, match=message):
        run(pm.PLANTED[name], tmp_path / name)
    assert not (tmp_path / name / "history.csv").exists()


def test_a_dynamic_model_gives_its_limit_through_mesh_k_max():
    cls = pm.PLANTED["dynamic_without_limit"]
    with pytest.raises(ContractError, match="implement mesh_k_max"):
        pm.problem(cls).k_max()
    given = type("given", (cls,), {"id": "test-given", "mesh_k_max": lambda self: 0.125})
    assert pm.problem(given).k_max() == 0.125
    bad = type("bad", (cls,), {"id": "test-bad", "mesh_k_max": lambda self: "0.1"})
    with pytest.raises(ContractError, match="not a positive number"):
        pm.problem(bad).k_max()


def test_a_field_of_its_own_leaving_its_declared_bounds_fails_the_run(tmp_path):
    bounded = pm.variant("bounded", state_bounds={"theta": (0.0, 0.15)})  # theta = t (2 - zeta)
    with pytest.raises(dd.ConvergenceError, match=r"theta left its bounds \[0, 0.15\]"):
        run(bounded, tmp_path / "bounded")
    assert run(pm.variant("wide", state_bounds={"theta": (0.0, 1.0)}),
               tmp_path / "wide")["status"] == "completed"


def test_studies_build_their_models_through_the_same_contracts(tmp_path):
    """A convergence study's levels and a sweep's points are built where every run's model is
    (problem/stages.py), so a broken declaration is refused there too, before any step (was: a
    study built its levels without the check; an unknown norm ended as a raw ValueError)."""
    for name in ("unknown_norm", "old_state_without_zeta"):
        problem = pm.problem(pm.PLANTED[name])
        with pytest.raises(ContractError, match=f"model test-{name}"):
            dd.converge(problem, str(tmp_path / f"c-{name}"), n=[2, 4], k=[0.05], ref_n=8,
                        ref_k=0.05, progress=False)
        assert not list((tmp_path / f"c-{name}").glob("*.csv"))
    # a sweep's points fail one by one, each with the contract's message and no step done
    summary = dd.sweep(pm.problem(pm.PLANTED["old_state_without_zeta"]), str(tmp_path / "s"),
                       {"kappa": [0.5, 1.0]}, progress=False, figures=False)
    assert summary["status"] == "failed" and summary["point_status"] == {"0": "failed",
                                                                         "1": "failed"}
    assert all("add ('zeta', 'zeta_old') to old_state" in m for m in summary["errors"].values())
    assert not list((tmp_path / "s").glob("point_*/history.csv"))


#: declarations of the wrong form or naming no Function: refused before the model is built
#: (were raw ValueError/AttributeError/TypeError from inside the constructor or the first
#: checkpoint, a bound silently ignored, or a name read letter by letter)
MALFORMED = {
    "old_state_not_pairs": (dict(old_state="u"), "old_state is 'u', not a tuple of"),
    "old_state_triple": (dict(old_state=(("u", "u_old", "v"), ("zeta", "zeta_old"))),
                         r"old_state holds \('u', 'u_old', 'v'\), not a \(Function, copy\) pair"),
    "old_state_self": (dict(old_state=(("u", "u"), ("zeta", "zeta_old"), ("theta", "theta_old"))),
                       "old_state pairs 'u' with itself"),
    "old_state_other_space": (dict(old_state=(("u", "zeta_old"), ("zeta", "u_old"),
                                              ("theta", "theta_old"))),
                              "a Function of another space"),
    "update_two_names": (dict(update=("u", "u_old")), "update is .*not None or \\(new, old, rate\\)"),
    "checkpoint_fields_text": (dict(checkpoint_fields="u"), "checkpoint_fields is 'u', not a tuple"),
    "checkpoint_fields_unknown": (dict(checkpoint_fields=("u", "zeta", "v", "nope")),
                                  "checkpoint_fields names 'nope', which is not set"),
    "history_columns_text": (dict(history_columns="theta_max"), "history_columns is 'theta_max'"),
    "state_bounds_unknown": (dict(state_bounds={"k": (0.0, 1.0)}), "state_bounds names 'k'"),
    "state_bounds_reversed": (dict(state_bounds={"theta": (1.0, 0.0)}), "lo <= hi"),
    "state_bounds_nan": (dict(state_bounds={"theta": (float("nan"), 1.0)}), "lo <= hi"),
    "state_bounds_number": (dict(state_bounds={"theta": 0.5}), "not a pair of numbers"),
    "state_bounds_list": (dict(state_bounds=[("theta", (0.0, 1.0))]), "not a dict"),
}


@pytest.mark.parametrize("name", sorted(MALFORMED))
def test_a_malformed_declaration_is_refused_before_the_model_is_built(tmp_path, name):
    attrs, message = MALFORMED[name]
    with pytest.raises(ContractError, match=message):
        run(pm.variant(name, **attrs), tmp_path / name)
    assert not (tmp_path / name / "history.csv").exists()


def test_check_model_reports_a_malformed_declaration():
    report = dd.check_model(pm.problem(pm.variant("bounds", state_bounds={"theta": 0.5})),
                            mpi=False)
    assert report.failed() == ["contracts"], str(report)
    assert "not a pair of numbers" in report["contracts"].detail
