"""The fast cases of the bad-input table (benchmarks/faults/bad_inputs.py), in this process:
each is refused before any work (one line, exit status 2, no file written or changed), fails
with its documented status (3, summary.json "failed") or warns, as the table expects; no
traceback, no file of the user's touched. And every JSON file of a run and of a study parses
with a strict parser (no bare NaN or Infinity)."""
import contextlib
import importlib.util
import io
import json
import os
import traceback
from pathlib import Path

import pytest

from damage_dolfinx import cli

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("bad_inputs",
                                               ROOT / "benchmarks" / "faults" / "bad_inputs.py")
bad_inputs = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(bad_inputs)

FAST = [c for c in bad_inputs.CASES if c["fast"]]


def in_process(args, cwd):
    """(exit status, stdout, stderr) of cli.main(args) run in ``cwd``; an exception that
    escapes is written to stderr as a traceback (the table counts it as such)."""
    out, err = io.StringIO(), io.StringIO()
    here = os.getcwd()
    os.chdir(cwd)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                status = cli.main([str(a) for a in args])
            except SystemExit as exc:
                status = exc.code
            except Exception:  # noqa: BLE001 - recorded, not raised
                err.write(traceback.format_exc())
                status = 1
    finally:
        os.chdir(here)
    return status, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def bases(tmp_path_factory):
    root = tmp_path_factory.mktemp("bases")

    def runner(args, cwd):
        status, _, err = in_process(args, cwd)
        assert status == 0, err
    return bad_inputs.make_bases(root, runner)


@pytest.mark.parametrize("case", FAST, ids=[c["id"] for c in FAST])
def test_bad_input(case, bases, tmp_path):
    result = bad_inputs.run_case(case, bases, tmp_path, runner=in_process)
    assert result["pass"], json.dumps(result, indent=1)


def _strict_files(folder):
    names = sorted(Path(folder).rglob("*.json"))
    assert names
    for path in names:
        bad_inputs._strict(path.read_text())  # raises on a bare NaN / Infinity
    return [p.name for p in names]


def test_every_json_of_a_run_and_a_study_is_strict(bases):
    assert {"summary.json", "manifest.json", "checkpoint.json"} <= set(_strict_files(bases["run"]))
    assert {"summary.json", "manifest.json"} <= set(_strict_files(bases["study"]))


def test_one_level_study_writes_null_rates_with_a_reason(tmp_path):
    status, _, err = in_process(["converge", "2.1-ex1", "--ref-n", "10", "--ref-k", "0.125",
                                 "--n", "5", "--k", "0.25", "--quiet", "--out", "o"], tmp_path)
    assert status == 0, err
    _strict_files(tmp_path / "o")
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["rates"]["h_plus_k_all"] is None
    assert summary["null_values"]["rates.h_plus_k_all"] == "NaN" and "rates_note" in summary


def test_every_argument_of_every_entry_point_has_a_rule():
    """Each keyword argument of run, steps, converge, sweep, read_mesh and from_gmsh is checked
    by the rule of its name (validation.ARGUMENTS) or by a check of its own (the problem, the
    grid, the levels, the mesh path and dimension, the gmsh model); a wrong type of each is
    refused with InputError naming it."""
    import inspect
    import numpy as np
    import damage_dolfinx as dd
    from damage_dolfinx.core import validation
    own = {"problem", "grid", "path", "dim", "model"}
    levels = {"n", "k"}  # converge: lists, by validation.levels
    for fn in (dd.run, dd.steps, dd.converge, dd.sweep, dd.read_mesh, dd.from_gmsh):
        names = set(inspect.signature(fn).parameters) - own
        if fn is dd.converge:
            names -= levels
        if fn is dd.sweep:  # **kwargs: the options of the sweep itself
            from damage_dolfinx.studies.sweep import sweep
            names = set(inspect.signature(sweep).parameters) - own
        assert names <= set(validation.ARGUMENTS), (fn.__name__, names - set(
            validation.ARGUMENTS))
    wrong = {"comm": "world", "on_step": 5, "out": None, "progress": "no", "point": -1,
             "ref_k": float("nan"), "n": np.float64(2.0)}
    for name, value in wrong.items():
        with pytest.raises(dd.InputError, match=name):
            validation.arguments(**{name: value})
    assert validation.arguments(n=np.int64(3), T=np.float32(0.5)) == {"n": 3, "T": 0.5}


def test_an_option_the_user_set_between_two_runs_is_kept_and_fingerprinted():
    """A solver default replaces only its own earlier value: an option the user set since (a
    script between two runs) stays, and the run fingerprint lists it (a restart with other
    result-changing PETSc options is refused), while the defaults are not listed."""
    from petsc4py import PETSc
    from damage_dolfinx.numerics import solvers
    from damage_dolfinx.runtime.fingerprint import given_options
    opts = PETSc.Options()
    try:
        solvers.set_default_options("mech_", {"ksp_type": "cg", "ksp_rtol": 1e-12})
        assert given_options() == []
        opts["mech_ksp_rtol"] = "1e-3"
        solvers.set_default_options("mech_", {"ksp_type": "cg", "ksp_rtol": 1e-12})
        assert opts.getString("mech_ksp_rtol") == "1e-3"
        assert given_options() == [["mech_ksp_rtol", "1e-3"]]
        opts["mech_ksp_monitor"] = ""  # a diagnostic changes no result
        assert given_options() == [["mech_ksp_rtol", "1e-3"]]
    finally:
        for name in ("mech_ksp_type", "mech_ksp_rtol", "mech_ksp_monitor"):
            opts.delValue(name)
            solvers._CODE_DEFAULTS.pop(name, None)
