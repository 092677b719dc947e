"""The fast cases of the table of the newest surfaces (benchmarks/faults/bad_inputs_surfaces.py)
in this process: each is refused before any work, fails with its status or stops as the table
accepts, with no traceback and no file of the user's touched. The slow cases (mpirun, signals,
studies, own processes) run with the table itself. Also: the API's and the command line's
defaults are one table, and the mechanisms behind the rows hold on their own."""
import importlib.util
import inspect
import sys
import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location(
    "bad_inputs_surfaces", ROOT / "benchmarks" / "faults" / "bad_inputs_surfaces.py")
surfaces = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(surfaces)

FAST = [c for c in surfaces.CASES if c["fast"]]


def in_process(args, cwd):
    from test_bad_inputs import in_process as run
    return run(args, cwd)


@pytest.fixture(scope="module")
def bases(tmp_path_factory):
    root = tmp_path_factory.mktemp("bases")

    def runner(args, cwd):
        status, _, err = in_process(args, cwd)
        assert status == 0, err
    return surfaces.bi.make_bases(root, runner)


@pytest.mark.parametrize("case", FAST, ids=[c["id"] for c in FAST])
def test_surface_case(case, bases, tmp_path):
    result = surfaces.run_case(case, bases, tmp_path, runner=in_process)
    assert result["pass"], json.dumps(result, indent=1)


def test_the_table_has_every_surface_and_enough_rows():
    classes = {c["cls"] for c in surfaces.CASES}
    assert {"callbacks", "defaults", "types", "fingerprints", "meshes", "signals"} <= classes
    assert len(surfaces.CASES) >= 120
    assert len({c["id"] for c in surfaces.CASES}) == len(surfaces.CASES)


def test_api_and_command_line_share_their_defaults():
    """validation.DEFAULTS is the one table: every public entry's keyword of that name and the
    command line's option default to it, and nothing replaces an earlier result by default."""
    import damage_dolfinx as dd
    from damage_dolfinx.cli import _parser
    from damage_dolfinx.core.validation import DEFAULTS
    assert DEFAULTS["overwrite"] is False and DEFAULTS["restart"] is False
    for fn in (dd.run, dd.steps, dd.converge):
        params = inspect.signature(fn).parameters
        for name, value in DEFAULTS.items():
            if name in params:
                assert params[name].default == value, (fn.__name__, name)
    parser = _parser()
    for command in (["run", "2.1-ex1", "--out", "o"], ["converge", "2.1-ex1", "--out", "o"]):
        args = parser.parse_args(command)
        assert args.overwrite is DEFAULTS["overwrite"] and args.restart is DEFAULTS["restart"]
        assert (not args.quiet) is DEFAULTS["progress"]


def test_a_callback_decision_is_agreed_by_every_rank():
    """runtime/callbacks.decide on one rank: a true value stops, a raise is raised, a truth
    that is not a plain yes or no and a sys.exit are the callback's errors."""
    import numpy as np
    from mpi4py import MPI
    from damage_dolfinx.runtime.callbacks import decide
    comm = MPI.COMM_SELF
    assert decide(comm, lambda: 1) is True and decide(comm, lambda: None) is False
    with pytest.raises(TypeError, match="truth"):
        decide(comm, lambda: np.array([1, 2]))
    with pytest.raises(RuntimeError, match="sys.exit"):
        decide(comm, lambda: sys.exit(0))
    with pytest.raises(KeyError):
        decide(comm, lambda: {}["x"])


def test_a_stored_stability_limit_is_checked_against_its_bounds():
    """stability_bound.cached_problem: an entry under another key, with k_max above the cheap
    upper bound (x100, inf), or below the proven lower bound is not believed."""
    from damage_dolfinx.numerics.stability import SAFETY, critical_time_step
    from damage_dolfinx.numerics.stability_bound import cached_problem
    omega2, m = 1e4, 1e9
    k = critical_time_step(omega2, m)
    good = {"key": "K", "omega2_max": omega2, "k_max": k, "k_max_proportional_formula": k,
            "k_suggested": SAFETY * k}
    bounds = {"omega2_B_upper": 2 * omega2, "omega2_contact_upper": 0.0,
              "k_max_lower_bound": 0.5 * k}
    upper = (1.5 * k, 0.5 * omega2)
    check = lambda v: cached_problem(v, "K", bounds, upper, m, critical_time_step, SAFETY)  # noqa: E731
    assert check(good) is None
    assert "key" in check(dict(good, key="other"))
    assert "k_max" in check(dict(good, k_max=100 * k, k_suggested=100 * SAFETY * k))
    assert "k_max" in check(dict(good, k_max=float("inf")))
    assert "k_max" in check(dict(good, k_max=0.1 * k, k_suggested=0.1 * SAFETY * k))
    assert "omega" in check(dict(good, omega2_max=omega2 / 100))


def test_a_parameter_keeps_the_type_of_its_default():
    import damage_dolfinx as dd
    p = dd.model_defaults("2.1")
    for change in ({"E": True}, {"stop_at_zeta_star": 1}, {"kappa": 1e-320}, {"E": None},
                   {"E": float("nan")}):
        with pytest.raises(dd.InputError):
            p.replace(**change)
    assert p.replace(E=2e4, L_trunc=float("inf"), stop_at_zeta_star=False).E == 2e4


def test_gather_takes_whole_functions_only():
    """dd.gather refuses, with one line, what is not a Function (was: a raw AttributeError) and
    a sub-function (was: DOLFINx's raw RuntimeError); a collapsed component is gathered."""
    import numpy as np
    from mpi4py import MPI
    from dolfinx import fem, mesh
    import damage_dolfinx as dd
    from damage_dolfinx.compat.spaces import vector_p1
    m = mesh.create_unit_square(MPI.COMM_WORLD, 4, 4)
    u = fem.Function(vector_p1(m))
    u.x.array[:] = np.arange(u.x.array.size)
    for bad, words in (("results/run", "takes a dolfinx.fem.Function, got str"),
                       (u.sub(0), "not a sub-function u.sub(i)")):
        with pytest.raises(dd.InputError, match=re.escape(words)):
            dd.gather(bad)
    coords, values = dd.gather(u.sub(0).collapse())
    whole = dd.gather(u)
    assert np.array_equal(coords, whole[0]) and np.array_equal(values[:, 0], whole[1][:, 0])
