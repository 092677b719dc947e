"""Gmsh physical names as boundary tags, and the step limit k_max before the run."""
import dataclasses

import pytest
import ufl
from mpi4py import MPI

import damage_dolfinx as dd
from damage_dolfinx.geometries.plate_with_hole import plate_with_hole
from damage_dolfinx.geometries.rectangle import rectangle, side


def _pull(x, t):
    return ufl.as_vector((10.0 * t, 0.0))


def test_physical_names_are_tags(tmp_path):
    plate = plate_with_hole(MPI.COMM_WORLD, 0.2)
    assert plate.names == {"left": 1, "right": 2, "bottom": 3, "top": 4, "hole": 5}
    by_name = dd.Problem(model="2.1", mesh=plate, T=0.1, k=0.05, traction=_pull,
                         boundaries={"clamped": "left", "traction": ["right"]})
    by_number = dataclasses.replace(by_name, boundaries={"clamped": 1, "traction": 2})
    a = dd.run(by_name, tmp_path / "a", progress=False, figures=False)
    b = dd.run(by_number, tmp_path / "b", progress=False, figures=False)
    assert a["final"] == b["final"]
    bad = dataclasses.replace(by_name, boundaries={"clamped": "lefty", "traction": "right"})
    with pytest.raises(dd.InputError) as refusal:
        dd.run(bad, tmp_path / "c", progress=False, figures=False)
    message = str(refusal.value)
    print(message)
    assert "'lefty' is not a physical name" in message and "'left'" in message
    assert "\n" not in message


def test_k_max_before_the_run(tmp_path):
    geometry = rectangle(MPI.COMM_WORLD, (0.0, 0.0), (2.0, 0.5), 8, 2, {3: side(1, 0.0)})
    block = dd.Problem(model="3.1", mesh=geometry, T=0.1, boundaries={"normal_compliance": 3},
                       body_force=lambda x, t: ufl.as_vector((0.0, -10.0)),
                       params={"c_nu": 1e4, "gap": 0.0})
    with pytest.raises(dd.InputError, match=r"problem\.k_max\(\) gives it"):
        dd.run(block, tmp_path / "a", progress=False)
    k_max = block.k_max()
    print(f"3.1 block: problem.k_max() = {k_max:.6g}")
    assert 0.02 > k_max
    with pytest.raises(dd.InputError) as refusal:
        dd.run(dataclasses.replace(block, k=0.02), tmp_path / "b", progress=False)
    assert f"k_max = {k_max:.4g}" in str(refusal.value)
    assert 0.1 / 8 < k_max
    summary = dd.run(dataclasses.replace(block, k=0.1 / 8), tmp_path / "c", progress=False,
                     figures=False)
    assert abs(summary["k_max"] - k_max) <= 1e-12 * k_max
    assert dd.Problem(model="2.2", mesh=geometry, T=1.0, params={"m_visc": 40.0}).k_max() == 0.05
    assert dd.Problem(model="2.1", mesh=geometry, T=1.0).k_max() == float("inf")
