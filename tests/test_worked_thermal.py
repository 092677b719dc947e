"""The worked temperature model (demos/demo_thermal_damage.py: a Kelvin-Voigt body with damage
and a temperature with its own heat equation): it passes dd.check_model (serially and against
2 ranks), its discrete heat balance holds to solver tolerance and fails for a heat step run
before the velocity step, a uniform case follows the scheme's recursion and fails for a damage
source of the total strain, and the temperature left out of the state is refused or caught."""
import dataclasses
import runpy
from pathlib import Path

import pytest

import damage_dolfinx as dd

DEMO = Path(__file__).resolve().parent.parent / "demos" / "demo_thermal_damage.py"
NS = runpy.run_path(str(DEMO), run_name="thermal_check")   # the model and problem, no run
Thermal, PROBLEM, heat_balance = NS["ThermalKelvinVoigt"], NS["problem"], NS["heat_balance"]
UNIFORM, uniform_defect = NS["uniform"], NS["uniform_defect"]
SHORT = dict(n=2, T=0.5)   # 10 steps of k = 0.05 on the 8 x 2 bar: damage and heat under way


def test_check_model_passes(tmp_path):
    report = dd.check_model(PROBLEM, tmp_path, mpi=False)
    assert report.ok, str(report)
    assert {c.name for c in report.checks if c.status == "pass"} >= {
        "contracts", "prefixes", "stability_limit", "run", "finite", "history_columns",
        "restart"}, str(report)
    checked = report["contracts"].detail          # the state check after every step
    assert "theta" in checked and "theta_old" in checked, checked


@pytest.mark.mpi
def test_check_model_serial_equals_two_ranks(tmp_path):
    report = dd.check_model(PROBLEM, tmp_path, steps=2, script=DEMO)
    assert report["serial_vs_2_ranks"].status == "pass", str(report)


def balance_of(problem, out):
    with dd.steps(problem, out, overwrite=True, progress=False, figures=False, **SHORT) as run:
        balance, rows = heat_balance(run, problem.k)
    assert run.summary["status"] == "completed"
    return balance, rows


class HeatTooEarly(Thermal):
    """A planted mistake: the heat step before the velocity step (its source then reads the
    previous step's velocity)."""
    id = "kv-thermal-heat-too-early"

    def scheme(self):
        damage, mech, heat = super().scheme()
        return damage, heat, mech


def test_heat_balance_holds_and_catches_a_heat_step_out_of_order(tmp_path):
    balance, rows = balance_of(PROBLEM, tmp_path / "right")
    produced = rows[-1][2]
    assert produced > 0.05 and rows[-1][3] < 0.99    # heat made, damage under way
    assert balance <= 1e-9
    wrong, _ = balance_of(dataclasses.replace(PROBLEM, model=HeatTooEarly), tmp_path / "wrong")
    assert wrong > 1e-3, wrong


class TotalStrainDamage(Thermal):
    """A planted mistake: the damage source of the total strain (thermal expansion damages)."""
    id = "kv-thermal-total-strain-damage"

    def damage_source(self, e, z):
        import ufl
        p, x = self.params, self.params.extra
        psi_q = ufl.min_value(ufl.inner(e, e), p.q_star)
        return (dd.Model.damage_source(self, e, z)
                - 0.5 * x["s_theta"] * p.lam_u * ufl.max_value(self.theta_old, 0.0) * psi_q)


def test_uniform_case_follows_the_recursion_and_catches_thermal_strain_damage(tmp_path):
    defect, (e, z, theta) = uniform_defect(UNIFORM, tmp_path / "right")
    assert theta > 1.0 and z < 0.9    # heated and damaged
    assert defect <= 1e-9
    wrong, _ = uniform_defect(dataclasses.replace(UNIFORM, model=TotalStrainDamage),
                              tmp_path / "wrong")
    assert wrong > 1e-3, wrong


class ThetaNotInState(Thermal):
    """A planted mistake: theta_{n-1} copied by the model itself, theta not in old_state nor
    in the checkpoint; its damage step declares that it reads theta_{n-1}."""
    id = "kv-thermal-theta-not-in-state"
    old_state = (("u", "u_old"), ("zeta", "zeta_old"))
    checkpoint_fields = ("u", "zeta", "v")

    def begin_step(self):
        self.theta_old.x.array[:] = self.theta.x.array


class ThetaHidden(ThetaNotInState):
    """The same, and the damage step's read of theta_{n-1} not declared either: no declaration
    shows it, the restart check does."""
    id = "kv-thermal-theta-hidden"

    def __init__(self, data):
        super().__init__(data)
        self.damage.previous_state = tuple(
            pair for pair in self.damage.previous_state if pair[0] is not self.theta)


def test_theta_left_out_of_the_state_is_refused_or_caught(tmp_path):
    refused = dd.check_model(dataclasses.replace(PROBLEM, model=ThetaNotInState), mpi=False)
    assert refused.failed() == ["contracts"], str(refused)
    assert "('theta', 'theta_old')" in refused["contracts"].detail, str(refused)
    caught = dd.check_model(dataclasses.replace(PROBLEM, model=ThetaHidden), mpi=False)
    assert caught.failed() == ["restart"], str(caught)
    assert "theta" in caught["restart"].detail, str(caught)
