"""The worked wear model (demos/demo_wear.py): its balances hold, it passes dd.check_model,
and the mistakes specific to a solution-dependent gap are caught: a gap frozen at its first
value (the load balance fails), the wear left out of the checkpoint (the restart check fails)."""
import runpy
from pathlib import Path

import numpy as np
import pytest
from dolfinx import fem

import damage_dolfinx as dd

DEMO = runpy.run_path(str(Path(__file__).resolve().parent.parent / "demos" / "demo_wear.py"),
                      run_name="demo_wear")
WEAR = DEMO["WearingKelvinVoigt"]


class FrozenGap(WEAR):
    """Planted: the gap of the mechanics is g_0 + w at the time the model was built (a copy
    of w, never updated), while the wear still grows."""
    id = "kv-archard-wear-frozen-gap"

    def gap(self):
        self._w_at_build = fem.Function(self.w.function_space, name="w_at_build")
        self._w_at_build.x.array[:] = self.w.x.array
        return self.gap0 + self._w_at_build


class WearNotCheckpointed(WEAR):
    """Planted: w updated in place by its own step, outside old_state and checkpoint_fields."""
    id = "kv-archard-wear-unsaved"
    old_state = (("u", "u_old"), ("zeta", "zeta_old"))

    def wear_step(self):
        self.w_old.x.array[:] = self.w.x.array
        super().wear_step()


def balances(model, tmp_path, **kw):
    problem = DEMO["make_problem"](model=model, n=2, T=0.3, **kw)
    worst, final, _, _ = DEMO["run_with_balances"](problem, tmp_path / model.id)
    load = DEMO["Q_LOAD"]
    return worst, abs(final["normal_force"] - load) / load, final


def test_wear_and_load_balances(tmp_path):
    worst, imbalance, final = balances(WEAR, tmp_path)
    assert final["wear_volume"] > 1e-3   # the gap has opened by much more than the tolerances
    assert worst <= 1e-12
    assert imbalance <= 1e-8


def test_no_wear_without_friction_work(tmp_path):
    worst, imbalance, final = balances(WEAR, tmp_path, k_w=0.0)
    assert final["wear_volume"] == 0.0 and imbalance <= 1e-8


def test_a_frozen_gap_is_detected(tmp_path):
    worst, imbalance, final = balances(FrozenGap, tmp_path)
    assert worst <= 1e-12          # the wear still sums its own rates ...
    assert imbalance > 1e-2        # ... but the foundation no longer carries the load


def test_the_model_passes_check_model():
    report = dd.check_model(DEMO["problem"], n=2, mpi=False)
    assert report.ok, str(report)


def test_wear_left_out_of_the_checkpoint_fails_the_restart():
    import dataclasses
    report = dd.check_model(dataclasses.replace(DEMO["problem"], model=WearNotCheckpointed),
                            n=2, mpi=False)
    assert report.failed() == ["restart"], str(report)


def test_a_negative_wear_coefficient_is_refused():
    with pytest.raises(dd.InputError, match="k_w"):
        DEMO["make_problem"](k_w=-1e-3).parameters()
