"""The masonry barrel vault in 3-D (2.1-ex3-vault): gmsh geometry (counts of the
structured grid, tag areas), equilibrium of the line load across the width, the width-averaged
section rotation, a coarse run that collapses with its hinge lines re-derived from the saved
fields, and serial = 2 ranks. Coarse meshes (h = 0.2); the study is benchmarks/studies/vault_3d.py."""
import json
import math

import numpy as np
import pytest
from mpi4py import MPI

from conftest import load_run, run_cli

H = 0.2
COARSE = {"width": 0.4, "n_width": 2}  # 3 x 75 x 2 grid, 2700 tetrahedra, 2736 dofs


def measures(geo):
    import ufl
    from dolfinx import fem
    from damage_dolfinx import compat
    msh = geo.mesh
    ds = ufl.Measure("ds", domain=msh, subdomain_data=geo.facet_tags)
    one = fem.Constant(msh, 1.0)
    out = {t: compat.assemble_scalar(one * ds(t), msh.comm) for t in range(1, 6)}
    out["volume"] = compat.assemble_scalar(one * ufl.dx(domain=msh), msh.comm)
    return out


def test_vault_geometry_counts_and_tags():
    from damage_dolfinx.geometries import GAMMA_C, GAMMA_D, GAMMA_N
    from damage_dolfinx.geometries.bridge import FREE, arch_bridge
    from damage_dolfinx.geometries.vault import END, barrel_vault
    from damage_dolfinx.core.parameters import InputError
    comm = MPI.COMM_WORLD
    geo = barrel_vault(comm, h=H, **COARSE)
    msh = geo.mesh
    n_r, n_t, n_w = geo.n_r, geo.n_theta, geo.n_width
    assert (n_r, n_t, n_w) == (3, 75, 2) and msh.topology.dim == 3
    # the structured grid: 2 triangles per quadrilateral, 3 tetrahedra per prism
    assert msh.topology.index_map(3).size_global == 6 * n_r * n_t * n_w
    assert msh.topology.index_map(0).size_global == (n_r + 1) * (n_t + 1) * (n_w + 1)
    m = measures(geo)
    W, t = COARSE["width"], geo.r_out - geo.r_in
    assert m[GAMMA_D] == pytest.approx(2 * t * W, rel=1e-12)        # both springing faces
    assert m[END] == pytest.approx(2 * m["volume"] / W, rel=1e-12)  # prismatic: ends = 2 V / W
    assert m[GAMMA_C] == 0.0
    # the loaded strip is the 2-D load patch of the same grid, extruded across the width
    arch = arch_bridge(comm, h=H)
    patch = measures(arch)[GAMMA_N]
    assert m[GAMMA_N] == pytest.approx(patch * W, rel=1e-12) and patch > 0
    ring = math.pi / 2 * (geo.r_out**2 - geo.r_in**2)
    assert m["volume"] == pytest.approx(ring * W, rel=5e-3)         # polygonal arcs
    # intrados + extrados: the rest of the boundary
    assert m[FREE] + m[GAMMA_N] == pytest.approx(
        (measures(arch)[FREE] + patch) * W, rel=1e-12)
    strain = measures(barrel_vault(comm, h=H, ends="plane_strain", **COARSE))
    assert strain[GAMMA_C] == pytest.approx(m[END], rel=1e-12) and strain[END] == 0.0
    with pytest.raises(InputError, match="ends"):
        barrel_vault(comm, h=H, ends="roller")
    with pytest.raises(InputError, match="width"):
        barrel_vault(comm, h=H, width=0.0)


def vault_stepper(monkeypatch, **geometry):
    from damage_dolfinx.catalogue import examples
    from damage_dolfinx.catalogue import bridge
    monkeypatch.setattr(bridge, "VAULT_GEOMETRY", {**COARSE, **geometry})
    return examples.get("2.1-ex3-vault").build(MPI.COMM_WORLD, h=H, k=0.001, T=0.01)


def test_line_load_and_self_weight_balance_the_reactions(monkeypatch):
    """Equilibrium at t_n with zeta = 1: the vertical reaction of the clamped springings equals
    rho g |Omega| + P(t_n) W: the line load P is per metre of width."""
    import ufl
    from dolfinx import fem
    from damage_dolfinx import compat
    from damage_dolfinx.forms.constitutive import eps
    from damage_dolfinx.forms.elastic_damage import stress
    from damage_dolfinx.geometries import GAMMA_D
    stepper = vault_stepper(monkeypatch)
    stepper.initialize()
    stepper._set_time(10)  # P = 45 kN per metre, zeta still 1
    stepper._solve_mech()
    p, msh = stepper.params, stepper.mesh
    V = stepper.u.function_space
    tags = stepper.data.geometry.facet_tags
    v = fem.Function(V)  # v = (0, 1, 0) at the clamped dofs, 0 elsewhere
    dofs = fem.locate_dofs_topological(V.sub(1), 2, tags.indices[tags.values == GAMMA_D])
    v.x.array[dofs] = 1.0
    f_B, f_N = stepper.loads()
    residual = (ufl.inner(stress(stepper.u, stepper.zeta, p.E, p.nu, p.zeta_star), eps(v)) * ufl.dx
                - ufl.inner(f_B, v) * ufl.dx - ufl.inner(f_N, v) * stepper._dsN)
    reaction = compat.assemble_scalar(residual, msh.comm)
    volume = compat.assemble_scalar(fem.Constant(msh, 1.0) * ufl.dx, msh.comm)
    assert stepper.load_kN() == pytest.approx(45.0)
    assert reaction == pytest.approx(2200 * 9.81 * volume + 45e3 * COARSE["width"], rel=1e-7)


def test_width_averaged_rotation_of_a_rigid_rotation(monkeypatch):
    """u = psi (-y, x, 0) about the arch centre: every section plane and every grid layer of it
    has the slope d u_t/d r = -psi."""
    from damage_dolfinx import compat
    stepper = vault_stepper(monkeypatch)
    psi = 1e-3
    compat.interpolate(stepper.u, lambda x: np.stack([-psi * x[1], psi * x[0], 0 * x[0]]))
    assert np.allclose(stepper.section_rotation(), -psi, rtol=1e-10, atol=0)
    assert stepper.layer_rotation().shape == (76, 3)
    assert np.allclose(stepper.layer_rotation(), -psi, rtol=1e-10, atol=0)


def run_coarse(out, monkeypatch=None, np_=1):
    if np_ == 1:
        from damage_dolfinx.runtime import runner
        from damage_dolfinx.catalogue import bridge
        monkeypatch.setattr(bridge, "VAULT_GEOMETRY", dict(COARSE))
        return runner.run("2.1-ex3-vault", out, h=H, progress=False, figures=False)
    code = ("import sys; from damage_dolfinx.runtime import runner; from damage_dolfinx.catalogue import "
            f"bridge; bridge.VAULT_GEOMETRY.update({COARSE!r}); runner.run('2.1-ex3-vault', "
            f"sys.argv[1], h={H}, progress=False, figures=False)")
    import subprocess
    import sys
    from conftest import ENV
    subprocess.run(["mpirun", "-n", str(np_), sys.executable, "-c", code, str(out)], env=ENV,
                   check=True, capture_output=True, timeout=300)
    return json.loads((out / "summary.json").read_text())


def test_coarse_vault_collapses_along_a_section_plane(tmp_path, monkeypatch):
    """Collapse = the first step at which every node of a section plane theta = theta_j (all
    radii, all layers across the width) is at zeta_star; D_j and the hinge lines re-derived from
    the saved nodal damage."""
    summary = run_coarse(tmp_path, monkeypatch)
    _, fields = load_run(tmp_path)
    assert summary["status"] == "collapse" and summary["failure_load_kN"] > 0
    assert summary["failure_load_kN"] == pytest.approx(4500 * summary["failure_time"], abs=1e-6)
    vault, b = summary["vault"], summary["bridge"]
    n_t, n_r, n_w = b["n_theta"], b["n_r"], vault["n_width"]
    assert b["nodes_per_section"] == [(n_r + 1) * (n_w + 1)] * 2
    assert vault["nodes_per_section_layer"] == [n_r + 1] * 2
    assert vault["failure_load_total_kN"] == pytest.approx(summary["failure_load_kN"] * 0.4)
    x, z = fields["zeta_coords"], fields["zeta"][:, 0]
    theta = np.arctan2(x[:, 1], x[:, 0])
    theta = np.where(theta <= -np.pi / 2, theta + 2 * np.pi, theta)
    j = np.rint((np.pi - theta) / (np.pi / n_t)).astype(int)
    layer = np.rint(x[:, 2] / (0.4 / n_w)).astype(int)
    zmax = np.full(n_t + 1, -np.inf)
    np.maximum.at(zmax, j, z)
    failed = np.flatnonzero(zmax <= 0.01 + 1e-9)
    assert failed.size >= 1 and failed.tolist() == [s["section"] for s in summary["failed_sections"]]
    eta = np.clip(z, 0.01, 1.0)
    D = 1 - np.bincount(j, weights=eta) / np.bincount(j)
    assert np.allclose(D, summary["failure_section_damage"], atol=1e-4)
    key = j * (n_w + 1) + layer
    D_l = (1 - np.bincount(key, weights=eta) / np.bincount(key)).reshape(n_t + 1, n_w + 1)
    assert np.allclose(D_l, vault["failure_section_damage_layers"], atol=1e-4)
    assert np.allclose(D_l.mean(axis=1), D, atol=1e-12)  # the same nodes in every layer
    hinges = summary["hinges"]
    assert len(hinges) >= 2 and summary["n_mechanism_hinges"] >= 2
    assert any(h["section"] in failed for h in hinges)
    for h in hinges:
        assert h["width_damage_min"] <= h["section_damage"] <= h["width_damage_max"]
        lo, hi = h["rotation_step_mrad_width"]
        assert lo - 1e-9 <= h["rotation_step_mrad"] <= hi + 1e-9
    # the unrolled faces: one value per (section, layer), the failed section at zeta_star
    z_out = np.asarray(vault["failure_zeta_extrados"])
    assert z_out.shape == (n_t + 1, n_w + 1)
    assert np.all(np.asarray(vault["failure_zeta_intrados"])[failed] <= 0.01 + 1e-4)


@pytest.mark.mpi
def test_coarse_vault_serial_equals_two_ranks(tmp_path, monkeypatch):
    s = run_coarse(tmp_path / "s", monkeypatch)
    p = run_coarse(tmp_path / "p", np_=2)
    assert (s["mpi_size"], p["mpi_size"]) == (1, 2)
    assert p["failure_load_kN"] == s["failure_load_kN"]
    assert p["failed_sections"] == s["failed_sections"]
    assert [h["section"] for h in p["hinges"]] == [h["section"] for h in s["hinges"]]
    assert [h["mechanism"] for h in p["hinges"]] == [h["mechanism"] for h in s["hinges"]]
    assert np.allclose([h["rotation_step_mrad"] for h in p["hinges"]],
                       [h["rotation_step_mrad"] for h in s["hinges"]], rtol=1e-6, atol=1e-6)
    assert np.allclose(p["vault"]["failure_section_damage_layers"],
                       s["vault"]["failure_section_damage_layers"], atol=2e-4)
