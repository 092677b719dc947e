"""The final scalars known before any work (validation_scalars.py) are those a run reports, for
every model of the package: the sweep refuses a plot of any other name before it writes
anything, and the two lists can never drift apart."""
import json
import subprocess
import sys

import pytest
import ufl
from mpi4py import MPI

import damage_dolfinx as dd
from conftest import ENV
from damage_dolfinx.catalogue.examples import catalogue
from damage_dolfinx.geometries.rectangle import rectangle, side
from damage_dolfinx.runtime.loop import Run
from damage_dolfinx.problem.scalars import final_scalar_names

#: one example of every model (n: a tiny structured mesh; None: the gmsh mesh as it is), with
#: the data that select columns (2.2-ex3 and 3.3-ex2: a probe; 3.2-ex2: two named contact
#: faces) and both dimensions
EXAMPLES = {"2.1-ex2a": None, "2.1-ex3": None, "2.2-ex3": 2, "2.3-ex1": 2, "2.4-ex1": 2,
            "3.1-ex1": 2, "3.2-ex2": 2, "3.3-ex2": 2, "2.2-ex1-3d": 1, "3.3-ex1-3d": 2}


def rect_mesh(comm, n):  # 1 left, 2 right, 3 bottom
    return rectangle(comm, (0.0, 0.0), (2.0, 0.5), 4 * n, n,
                     {1: side(0, 0.0), 2: side(0, 2.0), 3: side(1, 0.0)})


def own(model, roles, **params):
    return dd.Problem(model=model, mesh=rect_mesh, n=1, T=0.1, k=0.05, boundaries=roles,
                      traction=lambda x, t: ufl.as_vector((10.0 * t, 0.0)), params=params)


OWN = {
    "2.1 with a bilateral part": lambda: own("2.1", {"clamped": 1, "traction": 2,
                                                      "bilateral": 3}),
    "2.1 without contact": lambda: own("2.1", {"clamped": 1, "traction": 2}),
    "2.4 with coulomb": lambda: own("2.4", {"clamped": 1, "traction": 2, "coulomb": 3}),
    "2.3 without contact": lambda: own("2.3", {"clamped": 1, "traction": 2}),
}


def _finals(case, out, n=None):
    """(predicted names, the names of the run's final block) after one step."""
    comm = MPI.COMM_WORLD
    first = Run.prepare(case, out, n=n, progress=False, figures=False, comm=comm)
    k = first.configured.time.k
    r = Run.prepare(case, out, n=n, k=k, T=k, progress=False, figures=False, comm=comm)
    c = r.configured
    predicted = final_scalar_names(c, c.make_geometry(comm, c.n, c.h), comm)
    for _ in r.steps():
        pass
    final = [key for key, value in r.summary["final"].items()
             if isinstance(value, (int, float)) and not isinstance(value, bool)]
    return predicted, final


@pytest.mark.parametrize("example", list(EXAMPLES))
def test_catalogue_scalars_known_before_the_run(example, tmp_path):
    predicted, final = _finals(example, tmp_path / "o", EXAMPLES[example])
    assert sorted(predicted) == sorted(final)
    assert len(set(predicted)) == len(predicted)


def test_every_model_of_the_package_is_covered():
    models = {catalogue()[e].model_id for e in EXAMPLES}
    assert models == {ex.model_id for ex in catalogue().values()}


@pytest.mark.parametrize("name", list(OWN))
def test_own_problem_scalars_known_before_the_run(name, tmp_path):
    predicted, final = _finals(OWN[name](), tmp_path / "o")
    assert sorted(predicted) == sorted(final)


def test_sweep_refuses_an_unknown_plot_before_any_work(tmp_path):
    out = tmp_path / "s"
    with pytest.raises(dd.InputError, match="'bogus' is not one of the final scalars"):
        dd.sweep("2.1-ex2a", out, {"kappa": [1.0, 2.0]}, T=0.02, plot="bogus", progress=False)
    assert not out.exists()
    cmd = [sys.executable, "-m", "damage_dolfinx.cli", "sweep", "2.1-ex1", "--n", "5", "--k",
           "0.25", "--set", "kappa=1,2", "--plot", "bogus", "--out", str(out)]
    proc = subprocess.run(cmd, env=ENV, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.strip().count("\n") == 0 and "reports: u_L2" in proc.stderr
    assert proc.stdout == "" and not out.exists()
