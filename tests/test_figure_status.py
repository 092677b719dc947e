"""A computation's status is the computation's: a figure that cannot be drawn after a correct
run is a figure failure (listed in the summary; the run stays "completed"), and a mesh the
figures cannot draw (quadrilaterals, hexahedra) is refused before the run, not after it."""
import json
import math

import numpy as np
import pytest
from dolfinx import mesh as dm

import damage_dolfinx as dd
import planted_models as pm
from damage_dolfinx import compat
from damage_dolfinx.geometries import Geometry
from damage_dolfinx.geometries.rectangle import side
from damage_dolfinx.runtime import records


def test_a_figure_that_fails_leaves_the_run_completed(tmp_path, monkeypatch, capsys):
    def broken(*args, **kwargs):
        raise ValueError("cannot reshape array of size 800 into shape (3)")
    monkeypatch.setattr(records, "draw_figure", broken)
    summary = dd.run(pm.problem(), str(tmp_path / "run"), progress=False)
    assert summary["status"] == "completed"
    on_disk = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert on_disk["status"] == "completed"
    failures = on_disk["outputs"]["figure_failures"]
    assert failures and "cannot reshape" in failures[0]["error"]
    assert "not drawn at step" in capsys.readouterr().err


def quad_block(comm, n):
    msh = dm.create_rectangle(comm, [np.array([0.0, 0.0]), np.array([1.0, 0.25])],
                              [4 * n, n], dm.CellType.quadrilateral)
    facets, values = [], []
    for tag, marker in {4: side(0, 0.0), 2: side(1, 0.25), 3: side(1, 0.0)}.items():
        found = compat.locate_entities_boundary(msh, 1, marker)
        facets.append(found)
        values.append(np.full(found.size, tag))
    tags = compat.meshtags(msh, 1, np.concatenate(facets), np.concatenate(values))
    return Geometry(msh, tags, h=math.hypot(0.25 / n, 0.25 / n), description="quadrilaterals")


def test_a_quadrilateral_mesh_is_refused_before_the_run_when_figures_are_drawn(tmp_path):
    with pytest.raises(dd.InputError, match="quadrilateral cells: run it with figures=False"):
        dd.run(pm.problem(mesh=quad_block), str(tmp_path / "quads"), progress=False)
    assert not (tmp_path / "quads" / "history.csv").exists()
    summary = dd.run(pm.problem(mesh=quad_block), str(tmp_path / "quads"), progress=False,
                     figures=False)
    assert summary["status"] == "completed"
