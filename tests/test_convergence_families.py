"""converge on a gmsh (non-nested) mesh family: point evaluation on the reference mesh, the
norm and the comparison stated, serial = 2 ranks, a family that cannot be compared refused
before any step, progress=False silent; the point transfer exact for P1 fields."""
import json
import sys

import numpy as np
import pytest
import ufl
from mpi4py import MPI

from conftest import run_cli  # noqa: F401 (the environment of the subprocesses)

import damage_dolfinx as dd
from damage_dolfinx.geometries.plate_with_hole import plate_with_hole, plate_with_hole_family

SCRIPT = """
import sys, ufl, damage_dolfinx as dd
from damage_dolfinx.geometries.plate_with_hole import plate_with_hole_family
p = dd.Problem(model="2.1", mesh=plate_with_hole_family(h0=0.4), n=1, T=0.2, name="plate",
               boundaries={"clamped": "left", "traction": "right"},
               traction=lambda x, t: ufl.as_vector((40.0 * t, 0.0)),
               params={"E": 1e3, "kappa": 0.1, "lam_u_plus": 3e3, "lam_u_minus": 3e3,
                       "stop_at_zeta_star": False})
dd.converge(p, sys.argv[1], n=[1, 2], k=[0.1, 0.05], ref_n=4, ref_k=0.025, progress=False)
"""


def _problem(family):
    return dd.Problem(model="2.1", mesh=family, n=1, T=0.2, name="plate",
                      boundaries={"clamped": "left", "traction": "right"},
                      traction=lambda x, t: ufl.as_vector((40.0 * t, 0.0)),
                      params={"E": 1e3, "kappa": 0.1, "lam_u_plus": 3e3, "lam_u_minus": 3e3,
                              "stop_at_zeta_star": False})


def test_point_transfer_is_exact_for_linear_fields():
    from damage_dolfinx import compat
    from damage_dolfinx.studies.point_transfer import PointValues, ReferencePoints
    from dolfinx import fem
    coarse, fine = plate_with_hole(MPI.COMM_WORLD, 0.4), plate_with_hole(MPI.COMM_WORLD, 0.1)
    for space in (compat.scalar_p1, compat.vector_p1):
        Vc, Vf = space(coarse.mesh), space(fine.mesh)
        bs = Vc.dofmap.index_map_bs

        def linear(x):
            return np.vstack([1 + 2 * x[0] + 3 * x[1]] * bs)
        uc, uf, exact = fem.Function(Vc), fem.Function(Vf), fem.Function(Vf)
        compat.interpolate(uc, linear)
        compat.interpolate(exact, linear)
        points = ReferencePoints(Vf)
        side = PointValues(Vc, points.points)
        points.to_fine(side.grid_values(uc), uf)
        assert np.abs(uf.x.array - exact.x.array).max() < 1e-12
        assert side.outside == 0.0


def test_gmsh_family_serial_equals_two_ranks(tmp_path, capsys):
    import subprocess
    from conftest import ENV
    script = tmp_path / "study.py"
    script.write_text(SCRIPT)
    for np_, out in ((1, "s"), (2, "p")):
        cmd = [sys.executable, str(script), str(tmp_path / out)]
        if np_ > 1:
            cmd = ["mpirun", "-n", "2", *cmd]
        proc = subprocess.run(cmd, env=ENV, capture_output=True, text=True, timeout=600)
        assert proc.returncode == 0, proc.stderr
        assert proc.stdout == "", proc.stdout  # progress=False prints nothing
    serial = json.loads((tmp_path / "s" / "summary.json").read_text())
    parallel = json.loads((tmp_path / "p" / "summary.json").read_text())
    assert "point" in serial["comparison"] and "V norm" in serial["norm"]
    for a, b in zip(serial["errors"], parallel["errors"]):
        assert abs(a["error"] - b["error"]) <= 1e-8 * a["error"], (a, b)
    errors = {(r["n"], r["k"]): r["error"] for r in serial["errors"]}
    print("gmsh family errors:", errors, "rates:", serial["rates"])
    assert errors[(2, 0.05)] < errors[(1, 0.1)]
    assert serial["rates"]["h_plus_k_all"] > 0.3


def test_family_that_cannot_be_compared_is_refused_before_any_step(tmp_path):
    def shrinking(comm, n):  # the plate gets smaller with n: the meshes differ in domain
        return plate_with_hole(comm, 0.4 / n, L=2.0 / n, H=1.0 / n, r=0.25 / n)
    with pytest.raises(dd.InputError) as refusal:
        dd.converge(_problem(shrinking), tmp_path / "c", n=[1], k=[0.1], ref_n=2,
                    ref_k=0.05, progress=False)
    message = str(refusal.value)
    print(message)
    assert "cannot be compared" in message and "\n" not in message
    assert not (tmp_path / "c" / "summary.json").exists()
