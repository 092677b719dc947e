"""Section 2.1 Example 3 (masonry arch bridge): geometry, loads, the collapse
criterion checked against the saved fields, and serial = mpirun -n 2. Coarse meshes; the thesis-
size run and the sensitivity study live in benchmarks/studies/bridge_*.py."""
import csv
import json
import math

import numpy as np
import pytest
from mpi4py import MPI

from conftest import load_run, run_cli

COARSE = ["run", "2.1-ex3", "--h", "0.1", "--no-figures", "--quiet"]


def sections_from_fields(zeta_coords, n_theta):
    """Section index j = round((pi - theta)/dtheta) of every node (semicircle, centre (0,0))."""
    theta = np.arctan2(zeta_coords[:, 1], zeta_coords[:, 0])
    return np.rint((np.pi - theta) / (np.pi / n_theta)).astype(int)


def test_default_geometry_matches_thesis_mesh():
    """G3: 14 x 300 mapped grid = 8400 triangles, 4515 nodes; tags and the load patch."""
    from damage_dolfinx import compat
    from damage_dolfinx.geometries import GAMMA_D, GAMMA_N
    from damage_dolfinx.geometries.bridge import FREE, arch_bridge
    comm = MPI.COMM_WORLD
    geo = arch_bridge(comm)
    msh, tags = geo.mesh, geo.facet_tags
    assert msh.topology.index_map(2).size_global == 8400
    assert msh.topology.index_map(0).size_global == 4515
    assert (geo.n_r, geo.n_theta) == (14, 300)
    assert geo.r_in == pytest.approx(15 / math.pi - 0.35) and geo.r_out - geo.r_in == pytest.approx(0.7)
    count = {t: comm.allreduce(int(np.sum(tags.values == t))) for t in (GAMMA_D, GAMMA_N, FREE)}
    # two clamped springing faces of 14 facets, 2 x 300 ring faces minus the loaded ones
    assert count[GAMMA_D] == 28 and count[GAMMA_N] + count[FREE] == 600 and count[GAMMA_N] >= 1
    clamped = np.concatenate(comm.allgather(
        compat.facet_vertex_coords(msh, tags.indices[tags.values == GAMMA_D]).reshape(-1, 2)))
    assert np.allclose(clamped[:, 1], 0.0) and np.all(np.abs(clamped[:, 0]) >= geo.r_in - 1e-9)
    patch = np.concatenate(comm.allgather(
        compat.facet_vertex_coords(msh, tags.indices[tags.values == GAMMA_N])))
    # on the extrados, facet midpoints within x_load +- 0.05, x_load a quarter span from the left
    assert geo.x_load == pytest.approx(-(15 / math.pi - 0.35) / 2)
    assert np.allclose(np.hypot(patch[..., 0], patch[..., 1]), geo.r_out, rtol=1e-9)
    assert np.all(np.abs(patch.mean(axis=1)[:, 0] - geo.x_load) <= 0.05)
    length = np.sum(np.linalg.norm(patch[:, 1] - patch[:, 0], axis=1))
    assert 0.05 < length <= 0.11


def test_unstructured_variant_and_options():
    from damage_dolfinx.geometries import GAMMA_D, GAMMA_N
    from damage_dolfinx.geometries.bridge import arch_bridge
    from damage_dolfinx.core.parameters import InputError
    comm = MPI.COMM_WORLD
    geo = arch_bridge(comm, h=0.15, structured=False, fill=True, abutments=True)
    tags = geo.facet_tags
    for t in (GAMMA_D, GAMMA_N):
        assert comm.allreduce(int(np.sum(tags.values == t))) >= 1
    with pytest.raises(InputError, match="structured=False"):
        arch_bridge(comm, fill=True)
    with pytest.raises(InputError, match="rise"):
        arch_bridge(comm, span=4.0, rise=3.0)


def test_reactions_balance_self_weight_plus_load():
    """Equilibrium at t_n with zeta = 1: the support reaction equals rho g |Omega| + P(t_n),
    i.e. self weight is applied everywhere and the patch traction has resultant exactly P."""
    import ufl
    from dolfinx import fem
    from damage_dolfinx import compat
    from damage_dolfinx.catalogue import examples
    from damage_dolfinx.forms.constitutive import eps
    from damage_dolfinx.forms.elastic_damage import stress
    from damage_dolfinx.geometries import GAMMA_D
    stepper = examples.get("2.1-ex3").build(MPI.COMM_WORLD, h=0.2, k=0.001, T=0.01)
    stepper.initialize()
    stepper._set_time(10)  # P = 45 kN, zeta still 1
    stepper._solve_mech()
    p, msh = stepper.params, stepper.mesh
    V = stepper.u.function_space
    tags = stepper.data.geometry.facet_tags
    v = fem.Function(V)  # v = (0, 1) at the clamped dofs, 0 elsewhere
    dofs = fem.locate_dofs_topological(V.sub(1), 1, tags.indices[tags.values == GAMMA_D])
    v.x.array[dofs] = 1.0
    f_B, f_N = stepper.loads()
    residual = (ufl.inner(stress(stepper.u, stepper.zeta, p.E, p.nu, p.zeta_star), eps(v)) * ufl.dx
                - ufl.inner(f_B, v) * ufl.dx - ufl.inner(f_N, v) * stepper._dsN)
    reaction = compat.assemble_scalar(residual, msh.comm)
    area = compat.assemble_scalar(fem.Constant(msh, 1.0) * ufl.dx, msh.comm)
    expected = 2200 * 9.81 * area + 45e3
    assert reaction == pytest.approx(expected, rel=1e-8)
    assert 2200 * 9.81 * area == pytest.approx(2200 * 9.81 * math.pi / 2 * (
        stepper.data.geometry.r_out**2 - stepper.data.geometry.r_in**2), rel=2e-3)


def test_section_rotation_of_a_rigid_rotation():
    """u = psi (-y, x) (rigid rotation about the arch centre): u_t = -psi r on every section, so
    the measured slope d u_t/d r is -psi everywhere (the hinge rotations are its jumps)."""
    from damage_dolfinx import compat
    from damage_dolfinx.catalogue import examples
    stepper = examples.get("2.1-ex3").build(MPI.COMM_WORLD, h=0.2, k=0.001, T=0.01)
    psi = 1e-3
    compat.interpolate(stepper.u, lambda x: np.stack([-psi * x[1], psi * x[0]]))
    assert np.allclose(stepper.section_rotation(), -psi, rtol=1e-10, atol=0)


def test_collapse_detection_matches_saved_fields(tmp_path):
    """The run stops at the first step where a whole radial grid line is at zeta_star; the
    failure load, the failed sections and the hinges are re-derived from the saved fields."""
    from scipy.signal import find_peaks
    run_cli(COARSE + ["--out", tmp_path])
    summary, fields = load_run(tmp_path)
    assert summary["status"] == "collapse"
    n_theta, n_r = summary["bridge"]["n_theta"], summary["bridge"]["n_r"]
    assert (n_r, n_theta) == (7, 150) and summary["bridge"]["nodes_per_section"] == [8, 8]
    with open(tmp_path / "history.csv") as f:
        rows = list(csv.DictReader(f))
    last = rows[-1]
    # failure load = P at the stopping step = load_rate * t_n (resolution one increment)
    assert summary["failure_load_kN"] == pytest.approx(4500 * float(last["t"]), abs=1e-6)
    assert summary["failure_load_kN"] == pytest.approx(float(last["P_kN"]))
    assert summary["load_increment_kN"] == pytest.approx(4.5)
    assert summary["failure_step"] == int(last["step"]) == summary["steps_done"] < summary["num_steps"]
    # the per-section criterion, recomputed from the final nodal damage
    z = fields["zeta"][:, 0]
    j = sections_from_fields(fields["zeta_coords"], n_theta)
    assert np.all(np.bincount(j) == n_r + 1)
    zmax = np.full(n_theta + 1, -np.inf)
    np.maximum.at(zmax, j, z)
    failed = np.flatnonzero(zmax <= 0.01 + 1e-9)
    assert failed.tolist() == [s["section"] for s in summary["failed_sections"]]
    assert failed.size >= 1 and zmax.max() > 0.9  # one section failed, not the whole ring
    # ... and it was not met one step earlier
    assert float(last["weakest_section_zeta_max"]) <= 0.01 + 1e-9
    assert all(float(r["weakest_section_zeta_max"]) > 0.01 + 1e-9 for r in rows[:-1])
    # The damage stays in [zeta_star, 1] at every step (obstacle step, damage_bound)
    assert summary["damage_bound"] == "obstacle"
    assert summary["zeta_min_run"] >= 0.01 - 1e-10
    assert min(float(r["zeta_min"]) for r in rows) >= 0.01 - 1e-10
    assert max(float(r["zeta_max"]) for r in rows) <= 1.0 + 1e-10
    assert z.min() >= 0.01 - 1e-10 and z.max() <= 1.0 + 1e-10
    # hinges: peaks of D_j = 1 - mean eta_*(zeta) over each section
    D = 1 - np.bincount(j, weights=np.clip(z, 0.01, 1.0)) / np.bincount(j)
    assert np.allclose(D, summary["failure_section_damage"], atol=1e-4)
    distance = round(0.7 / (15 / math.pi * math.pi / n_theta))
    peaks, _ = find_peaks(np.r_[0, D, 0], height=0.3, prominence=0.2, distance=distance)
    assert [h["section"] for h in summary["hinges"]] == (peaks - 1).tolist()
    assert summary["n_hinges"] == len(summary["hinges"]) >= 2
    assert any(h["section"] in failed for h in summary["hinges"])
    # measured on this mesh (h = 0.1, 4500 kN/s): 94.5 kN, five peaks of D_j at 0, 25, 61
    # (under the load, x = -2.21 m, 64 deg), 146 and 179 deg; the left springing barely rotates
    # in the collapse step (2 % of the largest hinge rotation): the other four are the
    # four-hinge mechanism, faces opening alternately (benchmarks/README.md)
    assert summary["failure_load_kN"] == pytest.approx(94.5)
    hinges = summary["hinges"]
    assert [round(h["angle_deg"]) for h in hinges] == [0, 25, 61, 146, 179]
    assert [h["mechanism"] for h in hinges] == [False, True, True, True, True]
    assert summary["n_mechanism_hinges"] == 4
    assert [h["opening_face"] for h in hinges[1:]] == ["extrados", "intrados", "extrados", "intrados"]
    # force-displacement: the loaded point goes down, faster and faster (softening)
    u = np.array([float(r["u_load_y"]) for r in rows])
    assert np.all(np.diff(u) < 0)
    assert (u[-1] - u[-2]) < 3 * (u[1] - u[0])


def test_literal_linear_step_leaves_the_admissible_set(tmp_path):
    """--reading literal (= --set damage_bound=none) keeps the linear step (2.20): with the thesis
    data the source violates (2.11) and zeta_n falls far below zeta_star (beyond -100 on this
    mesh), which is why the default (evidence) solves the step as the obstacle problem over
    [zeta_star, 1]. Such a state cannot be right: the run stops as failed (exit 3), saying so."""
    proc = run_cli(COARSE + ["--reading", "literal", "--out", tmp_path], check=False)
    assert proc.returncode == 3, proc.stderr
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["damage_bound"] == "none" and summary["status"] == "failed"
    assert "zeta left [zeta_star, 1]" in summary["error"]


def test_damage_bound_is_checked(tmp_path):
    from damage_dolfinx.core.parameters import InputError
    from damage_dolfinx.models.bridge_2_1 import check_bridge_parameters
    with pytest.raises(InputError, match="damage_bound"):
        check_bridge_parameters({"damage_bound": "projection"})


@pytest.mark.mpi
def test_failure_load_serial_equals_two_ranks(tmp_path):
    run_cli(COARSE + ["--out", tmp_path / "s"])
    run_cli(COARSE + ["--out", tmp_path / "p"], np_=2)
    s = json.loads((tmp_path / "s" / "summary.json").read_text())
    p = json.loads((tmp_path / "p" / "summary.json").read_text())
    assert (s["mpi_size"], p["mpi_size"]) == (1, 2)
    assert abs(p["failure_load_kN"] - s["failure_load_kN"]) <= s["load_increment_kN"] + 1e-9
    assert p["failure_load_kN"] == s["failure_load_kN"]  # in practice identical
    assert [h["section"] for h in p["hinges"]] == [h["section"] for h in s["hinges"]]
    assert p["failed_sections"] == s["failed_sections"]
    assert [h["mechanism"] for h in p["hinges"]] == [h["mechanism"] for h in s["hinges"]]
    assert np.allclose([h["rotation_step_mrad"] for h in p["hinges"]],
                       [h["rotation_step_mrad"] for h in s["hinges"]], rtol=1e-6, atol=1e-6)
    assert p["zeta_min_run"] >= 0.01 - 1e-10
