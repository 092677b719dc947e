"""The worked adhesion model (demos/demo_adhesion.py): a bonding field beta on Gamma_C only, with
its own evolution law, on a Kelvin-Voigt body with damage. It passes dd.check_model; its physics
check (beta at every node of Gamma_C against the closed form of its ODE for the computed
separation history, and the foundation's traction against the pull) passes, and fails for a
planted explicit Euler law; a bonding field that leaves [0, 1] stops the run (state_bounds), and
one left out of the checkpoint fails the restart check."""
import dataclasses
import runpy
from pathlib import Path

import numpy as np
import pytest

import damage_dolfinx as dd

DEMO = Path(__file__).resolve().parent.parent / "demos" / "demo_adhesion.py"
demo = runpy.run_path(str(DEMO), run_name="test")
Adhesive = demo["AdhesiveKelvinVoigt"]


class ExplicitEuler(Adhesive):
    """A planted mistake: beta_n = beta_{n-1} - k (gamma beta_{n-1} R^2 - eps_a)_+ (explicit):
    it leads the closed form, and leaves [0, 1] once k gamma R^2 > 1."""
    id = "kv-adhesion-explicit"

    def adhesion_step(self):
        x = self.params.extra
        a = x["gamma_nu"] * self.nodal_separation(self.u_old) ** 2
        old = self.beta.x.array[self.nodes]
        self.beta.x.array[self.nodes] = old - self.k * np.maximum(a * old - x["eps_a"], 0.0)


class NotCheckpointed(Adhesive):
    """A planted mistake: beta, updated in place, left out of the checkpoint."""
    id = "kv-adhesion-no-beta-checkpoint"
    checkpoint_fields = ("u", "zeta", "v")


def problem(model=Adhesive, q=demo["Q_LOAD"], **kw):
    return dataclasses.replace(demo["problem"], model=model, traction=demo["pull"](q), **kw)


def physics(p, out):
    """The demo's checks on problem p: (imbalance, largest error/bound, beta below the closed
    form)."""
    times, betas, separations = [], [], []
    with dd.steps(p, out, overwrite=True, progress=False, figures=False) as run:
        for step in run:
            x_c, beta, u_nu = demo["gamma_c_history"](step)
            times.append(step.t)
            betas.append(beta)
            separations.append(u_nu)
            force = step.contact_resultant()[1]
    error, bound, ratio, _ = demo["closed_form_check"](
        np.array(times), np.array(betas), np.array(separations), p.model.defaults().extra)
    load = demo["Q_LOAD"] * times[-1]
    return abs(force - load) / load, ratio.max(), max(0.0, -ratio.min())


def test_check_model_passes():
    report = dd.check_model(problem(n=4), mpi=False)
    assert report.ok, str(report)
    assert "beta" in report["contracts"].detail      # beta is part of the checked state


def test_the_physics_check_passes_and_fails_for_a_wrong_law(tmp_path):
    imbalance, ratio, below = physics(problem(n=4, T=0.8, k=0.04), tmp_path / "right")
    assert imbalance <= 1e-8 and ratio <= 1.0 and below <= 1e-6, (imbalance, ratio, below)
    imbalance, ratio, below = physics(problem(ExplicitEuler, n=4, T=0.8, k=0.04), tmp_path / "wrong")
    assert imbalance <= 1e-8         # the mechanics balance; the law of beta is wrong
    assert below > 1e-3, below       # explicit Euler leads the closed form


def test_beta_outside_its_bounds_stops_the_run():
    report = dd.check_model(problem(ExplicitEuler, q=2000.0, n=2), mpi=False)
    assert "run" in report.failed(), str(report)
    assert "beta left its bounds [0, 1] (state_bounds)" in report["run"].detail


def test_beta_left_out_of_the_checkpoint_fails_the_restart_check():
    report = dd.check_model(problem(NotCheckpointed, q=100.0, n=2), mpi=False)
    assert report.failed() == ["restart"], str(report)
    # restarted with beta never set (0: no bond), the pulled block has nothing to hold it
    assert "the run restarted at step 2 failed" in report["restart"].detail
    assert "checkpoint_fields" in report["restart"].fix


def test_the_error_norm_on_gamma_c():
    """||f||_{L2(Gamma_C)} of f = x + 5 y on the block (Gamma_C: y = 0, 0 < x < 1) is
    sqrt(1/3): the values off Gamma_C do not count."""
    from mpi4py import MPI
    import ufl
    from dolfinx import fem
    from damage_dolfinx.viz.post import ComponentNorm
    geometry = demo["block"](MPI.COMM_WORLD, 2)
    Z = dd.blocks.scalar_p1(geometry.mesh)
    f, zero = fem.Function(Z), fem.Function(Z)
    x = ufl.SpatialCoordinate(geometry.mesh)
    dd.blocks.interpolate(f, dd.blocks.expression(x[0] + 5.0 * x[1], Z))
    norm = ComponentNorm(f, "L2_GammaC", geometry.facet_tags)
    assert abs(norm(zero) - np.sqrt(1.0 / 3.0)) < 1e-12
    assert abs(ComponentNorm(f, "L2")(zero) - np.sqrt(
        fem.assemble_scalar(fem.form(f * f * ufl.dx)))) < 1e-12
    with pytest.raises(ValueError, match="facet tags"):
        ComponentNorm(f, "L2_GammaC")
