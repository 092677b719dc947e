"""Section 3.3: with zeta = 1 the scheme is the Section 3.1 scheme; the velocity step equals an
independently assembled system with the NEW damage in the viscosity and the old one elsewhere;
the contact impulse scales with eta_*(zeta); bounds [zeta_star, 1]; serial = mpirun -n 2;
the central damage of Example 2 heals."""
import numpy as np
import pytest
import ufl
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from conftest import load_run, rel_diff, run_cli, serial_and_two_ranks
from damage_dolfinx import compat
from damage_dolfinx.geometries import GAMMA_C, GAMMA_D, GAMMA_N
from damage_dolfinx.geometries.rectangle import rectangle, side
from damage_dolfinx.core.parameters import ModelParameters
from damage_dolfinx.problem.problem import Problem
from damage_dolfinx.models.fully_damageable_3_3 import FullyDamageableContact


def _params(lam_u=0.0, **extra):
    """3.3 Ex. 1 data with rho = 1 (so that the body moves and touches the foundation)."""
    return ModelParameters(
        E=100.0, nu=0.3, kappa=1.0, zeta_star=0.01, q_star=1000.0, variant="A", lam_D=0.0,
        lam_u=lam_u, lam_w=0.0, L_trunc=1000.0, stop_at_zeta_star=False,
        extra={"rho": 1.0, "m_visc": 1.0, "c_nu": 2e3, "gap": 0.0, "damage_active": True,
               "stability_check": "off", "elastic_term": "explicit", **extra})


def _square(n=4):
    return rectangle(MPI.COMM_WORLD, (0, 0), (6, 6), n, n, {
        GAMMA_D: lambda x: side(0, 0.0)(x) | side(0, 6.0)(x), GAMMA_N: side(1, 6.0),
        GAMMA_C: side(1, 0.0)})


def _data(params, k, T, geometry=None, traction=(0.0, -10.0), zeta0=1.0):
    return Problem("3.3", geometry or _square(), T, k=k, params=params, name="3.3-test",
                       traction=lambda x, t: ufl.as_vector((traction[0] * t, traction[1] * t)),
                       zeta0=zeta0)


def _run(stepper):
    stepper.initialize()
    while stepper.n < stepper.num_steps:
        stepper.advance()
    return stepper


def test_zeta_one_equals_section_3_1():
    """No damage evolution (lam = 0, zeta_0 = 1): the 3.3 fields are the 3.1 fields."""
    try:
        from damage_dolfinx.models.dynamic_3_1 import DynamicKelvinVoigt
    except ImportError as exc:  # pragma: no cover
        pytest.skip(f"Section 3.1 stepper not available: {exc}")
    geo = _square(4)
    data = _data(_params(), 0.01, 0.3, geo, traction=(5.0, -40.0))
    s33 = _run(FullyDamageableContact(data))
    s31 = _run(DynamicKelvinVoigt(_data(_params(), 0.01, 0.3, geo, traction=(5.0, -40.0)),
                                  mech_prefix="s31_mech_", damage_prefix="s31_damage_"))
    assert s33.scalars()["penetration_max"] > 1e-4  # the contact term is active
    assert np.all(s33.zeta.x.array == 1.0)
    for a, b in ((s33.u, s31.u), (s33.v, s31.v)):
        d = rel_diff(a.x.array, b.x.array)
        print(f"{a.name}: 3.3 vs 3.1 relative difference {d:.2e}")
        assert d < 1e-9, a.name


def _independent_velocity(s):
    """(3.159) written again from the thesis, plain UFL, with the stepper's zeta_n, zeta_{n-1},
    u_{n-1}, v_{n-1}; solved by LU. ``swap``: zeta_{n-1} in the viscosity (the wrong order)."""
    p, x = s.params, s.params.extra
    V = s.v.function_space
    v, w = ufl.TrialFunction(V), ufl.TestFunction(V)
    E, nu, m, rho, k, c = p.E, p.nu, x["m_visc"], x["rho"], s.k, x["c_nu"]
    B = lambda e: E * nu / (1 - nu**2) * ufl.tr(e) * ufl.Identity(2) + E / (1 + nu) * e  # noqa
    ep = lambda f: ufl.sym(ufl.grad(f))  # noqa
    clipL = lambda t: ufl.as_matrix([[ufl.max_value(-p.L_trunc, ufl.min_value(p.L_trunc, t[i, j]))  # noqa
                                      for j in range(2)] for i in range(2)])
    n = ufl.FacetNormal(s.mesh)
    ds = ufl.Measure("ds", domain=s.mesh, subdomain_data=s.data.geometry.facet_tags)
    q = {"quadrature_degree": 2}
    tn = s.t
    out = []
    for z_visc in (s.zeta, s.zeta_old):
        a = rho / k * ufl.inner(v, w) * ufl.dx + z_visc * ufl.inner(B(ep(v)), ep(w)) / m * ufl.dx
        L = (rho / k * ufl.inner(s.v_old, w) * ufl.dx
             - s.zeta_old * ufl.inner(clipL(B(ep(s.u_old))), ep(w)) * ufl.dx(metadata=q)
             - s.zeta_old * c * ufl.max_value(ufl.dot(s.u_old, n), 0.0) * ufl.dot(w, n)
             * ds(GAMMA_C, metadata=q)
             + ufl.inner(ufl.as_vector((5.0 * tn, -40.0 * tn)), w) * ds(GAMMA_N))
        out.append(_lu_solve(a, L, s.bcs, V))
    return out


def _lu_solve(a, L, bcs, V):
    a, L = compat.form(a), compat.form(L)
    A, b = compat.create_matrix(a), compat.create_vector(L)
    compat.assemble_matrix(A, a, bcs)
    A.assemble()
    compat.assemble_vector(b, L)
    compat.apply_lifting(b, a, bcs)
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    compat.set_bc(b, bcs)
    ksp = PETSc.KSP().create(A.getComm())
    ksp.setOperators(A)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    u = fem.Function(V)
    ksp.solve(b, compat.petsc_vec(u))
    u.x.scatter_forward()
    return u.x.array.copy()


def test_velocity_step_against_independent_system():
    """The damaged step (3.159): viscosity with zeta_n, elasticity and contact with zeta_{n-1}."""
    s = FullyDamageableContact(_data(_params(lam_u=2e6), 0.01, 1.0, traction=(5.0, -40.0)))
    s.initialize()
    for _ in range(12):
        s.advance()
    assert s.zeta.x.array.min() < 0.9 and s.scalars()["penetration_max"] > 0  # damaged, in contact
    right, swapped = _independent_velocity(s)
    d_right, d_swap = rel_diff(s.v.x.array, right), rel_diff(s.v.x.array, swapped)
    print(f"v_n vs independent system: {d_right:.2e}; with zeta_(n-1) in the viscosity: {d_swap:.2e}")
    assert d_right < 1e-9
    assert d_swap > 1e3 * d_right


@pytest.mark.parametrize("zeta0", [1.0, 0.5, 0.2])
def test_contact_impulse_scales_with_damage(zeta0):
    """Free block (0,1)^2 overlapping the foundation by g0 (gap = -g0), at rest, no load: after
    one step the momentum is k times the contact force, int rho v_2 = k eta_*(zeta) c_nu g0
    (test field e_2: eps(e_2) = 0, so viscosity and elasticity drop out)."""
    g0, c_nu, k = 1e-3, 1e4, 1e-3
    geo = rectangle(MPI.COMM_WORLD, (0, 0), (1, 1), 4, 4, {GAMMA_C: side(1, 0.0)})
    params = _params(c_nu=c_nu, gap=-g0)
    data = Problem("3.3", geo, k, k=k, params=params, name="3.3-impulse", zeta0=zeta0)
    s = _run(FullyDamageableContact(data))
    momentum = compat.assemble_scalar(compat.form(s.v[1] * ufl.dx), s.comm)
    expected = k * zeta0 * c_nu * g0 * 1.0
    print(f"zeta0 = {zeta0}: momentum {momentum:.6e}, k eta c g0 = {expected:.6e}")
    assert np.all(np.abs(s.zeta.x.array - zeta0) < 1e-12)
    assert abs(momentum - expected) < 1e-9 * expected


@pytest.mark.mpi
def test_bounds_and_serial_equals_two_ranks_ex1(tmp_path):
    """Ex. 1 with a strong damage source: zeta reaches zeta_star and never leaves [zeta_star, 1];
    serial = 2 ranks."""
    (_, s), _ = serial_and_two_ranks(tmp_path, [
        "run", "3.3-ex1", "--n", "8", "--k", "0.05", "--T", "0.5", "--set", "lam_u=1e6", "--set", "rho=1",
        "--no-figures", "--quiet"])
    assert s["zeta"].min() >= 0.01 - 1e-12 and s["zeta"].max() <= 1 + 1e-12
    assert s["zeta"].min() <= 0.01 + 1e-9
    with open(tmp_path / "s" / "history.csv") as f:
        import csv
        rows = list(csv.DictReader(f))
    assert min(float(r["zeta_min"]) for r in rows) >= 0.01 - 1e-12
    assert max(float(r["zeta_max"]) for r in rows) <= 1 + 1e-12


@pytest.mark.mpi
def test_wrench_serial_equals_two_ranks(tmp_path):
    """Coarse wrench, 20 explicit steps."""
    (summary, s), (psum, _) = serial_and_two_ranks(tmp_path, [
        "run", "3.3-ex3", "--h", "0.5", "--k", "1e-5", "--T", "2e-4", "--no-figures", "--quiet"],
        fields=("u", "zeta"))
    assert summary["k_over_k_max"] < 1 and np.abs(s["u"]).max() > 0
    assert summary["max_penetration"] == pytest.approx(psum["max_penetration"], rel=1e-6)


def test_example2_central_damage_heals(tmp_path):
    """Ex. 2 (a), first 0.05 s: the initially damaged centre (zeta = 0.1) mends by diffusion
    (lam_D = 0) while the top corner stays nearly sound."""
    run_cli(["run", "3.3-ex2", "--T", "0.05", "--no-figures", "--quiet", "--out", tmp_path])
    summary, _ = load_run(tmp_path)
    prof = summary["profiles"]
    x1 = np.array(prof["x1"])
    centre = np.argmin(np.abs(x1 - 3.0))
    z0, z_end = prof["zeta"][0][centre], prof["last_zeta"][centre]
    # k lies below the no-eigensolve bound k_max_lower_bound <= k_max: the run does not compute
    # k_max; here it is, eigensolved on the run's mesh
    k_max = summary["k_max"]
    if k_max is None:
        from damage_dolfinx.catalogue import examples
        from damage_dolfinx.numerics.stability_bound import exact_estimates
        assert summary["k"] <= summary["k_max_lower_bound"]
        with exact_estimates():
            k_max = examples.get("3.3-ex2").build(
                MPI.COMM_WORLD, k=summary["k"], T=0.05).stability["k_max"]
        assert k_max >= summary["k_max_lower_bound"]
    print(f"zeta(3,3): t = 0 {z0:.3f}, t = {prof['last_t']:.3g} {z_end:.3f}; "
          f"k = {summary['k']:g}, k_max = {k_max:.3g}")
    assert prof["x2"] == 3.0 and z0 == pytest.approx(0.1)
    assert z_end > 0.2
    assert summary["k"] < 0.8 * k_max
    # the probe is a mesh vertex: its coordinates carry the mesh generator's round-off
    # (-8e-18 instead of 0 on DOLFINx 0.11)
    assert summary["probe"] == pytest.approx([0.0, 6.0], abs=1e-12) and summary["final"]["zeta_probe"] > 0.99


def test_implicit_variant_close_for_small_k():
    """The G33 deviation agrees with the thesis scheme to O(k) for a small k."""
    base = _square(4)
    out = {}
    for term in ("explicit", "implicit"):  # own prefix: the solvers' PETSc defaults differ
        s = _run(FullyDamageableContact(_data(_params(lam_u=2e3, elastic_term=term), 0.002, 0.2,
                                              base, traction=(5.0, -40.0)),
                                        mech_prefix=f"{term}_mech_"))
        out[term] = s.u.x.array.copy()
    d = rel_diff(out["implicit"], out["explicit"])
    print(f"implicit vs explicit, k = 0.002: {d:.2e}")
    assert 0 < d < 5e-2


def test_bad_elastic_term_is_refused(tmp_path):
    proc = run_cli(["run", "3.3-ex1", "--n", "4", "--set", "elastic_term=semi", "--quiet",
                    "--out", tmp_path], check=False)
    assert proc.returncode == 2 and "elastic_term" in proc.stderr


def test_fast_velocity_matrix_equals_reassembly():
    """The matrix of (3.159) updated from the nodal zeta_n by the precomputed sparse
    map equals the re-assembled one to round-off, Dirichlet rows included, for any zeta in K^h;
    an unchanged zeta leaves the matrix untouched."""
    from damage_dolfinx.numerics.zeta_linear import VelocitySolver
    s = FullyDamageableContact(_data(_params(), 0.01, 0.05, _square(6)))
    if MPI.COMM_WORLD.size > 1:
        pytest.skip("the sparse map is serial; in parallel the matrix is re-assembled")
    assert isinstance(s.mech, VelocitySolver) and s.mech.bcs
    rng = np.random.default_rng(1)
    ref = compat.create_matrix(s.mech.a)
    for _ in range(3):
        s.zeta.x.array[:] = rng.uniform(s.params.zeta_star, 1.0, s.zeta.x.array.size)
        s.mech.assemble_matrix()
        ref.zeroEntries()
        compat.assemble_matrix(ref, s.mech.a, s.mech.bcs)
        ref.assemble()
        fast, full = s.mech.A.getValuesCSR(), ref.getValuesCSR()
        assert all(np.array_equal(a, b) for a, b in zip(fast[:2], full[:2]))
        d = np.abs(fast[2] - full[2]).max() / np.abs(full[2]).max()
        print(f"fast update vs re-assembly: relative difference {d:.1e}")
        assert d < 1e-13
    assert not s.mech.fast.update(s.zeta.x.array)  # same zeta: no update


def test_fast_velocity_rhs_equals_assembly():
    """Phi_L = identity (L_trunc = inf, the wrench): the right-hand side of (3.159)
    as rho/k M v_{n-1} - K_B(zeta_{n-1}) u_{n-1} + assembled contact and load equals the
    assembled l to round-off, with the contact term active."""
    from damage_dolfinx.numerics.solvers import LinearSolver
    if MPI.COMM_WORLD.size > 1:
        pytest.skip("the sparse maps are serial; in parallel l is assembled")
    params = _params().replace(L_trunc=float("inf"))
    s = _run(FullyDamageableContact(_data(params, 0.01, 0.3, _square(6), traction=(5.0, -40.0))))
    assert s.mech.rhs is not None and s.scalars()["penetration_max"] > 1e-4
    rng = np.random.default_rng(2)
    for _ in range(3):
        s.zeta_old.x.array[:] = rng.uniform(params.zeta_star, 1.0, s.zeta.x.array.size)
        s.u_old.x.array[:] = s.u.x.array * rng.uniform(0.5, 1.5, s.u.x.array.size)
        s.v_old.x.array[:] = s.v.x.array * rng.uniform(0.5, 1.5, s.v.x.array.size)
        s.mech.assemble_rhs()
        fast = s.mech.b.array.copy()
        LinearSolver.assemble_rhs(s.mech)
        d = np.abs(fast - s.mech.b.array).max() / np.abs(s.mech.b.array).max()
        print(f"fast right-hand side vs assembly: relative difference {d:.1e}")
        assert d < 1e-13


WRENCH = ["run", "3.3-ex3", "--h", "0.5", "--k", "1e-5", "--no-figures", "--quiet"]


def _rows(out):
    import csv
    with open(out / "history.csv") as f:
        return {int(r["step"]): {k: v for k, v in r.items() if k != "step_time_s"}
                for r in csv.DictReader(f)}


def test_history_cadence_and_restart(tmp_path):
    """With --history-every 7 the rows are those of the run with a row per step at
    steps 0, 7, 14, ... and the last, every value equal; the maximal interpenetration over all
    steps (tracked between rows) and the final state are the same. A run stopped at step 15
    and continued with --restart ends with the same rows (plus its row at 15), fields and
    maximum."""
    run_cli(WRENCH + ["--T", "3e-4", "--history-every", "1", "--out", tmp_path / "all"])
    run_cli(WRENCH + ["--T", "3e-4", "--history-every", "7", "--out", tmp_path / "every7"])
    run_cli(WRENCH + ["--T", "1.5e-4", "--history-every", "7", "--out", tmp_path / "resumed"])
    run_cli(WRENCH + ["--T", "3e-4", "--history-every", "7", "--restart",
                      "--out", tmp_path / "resumed"])
    every, sparse, resumed = (_rows(tmp_path / d) for d in ("all", "every7", "resumed"))
    assert sorted(sparse) == [0, 7, 14, 21, 28, 30]
    assert all(sparse[n] == every[n] for n in sparse)
    assert sorted(resumed) == sorted(set(sparse) | {15})
    assert all(resumed[n] == every[n] for n in resumed)
    (s_all, f_all), (s_7, f_7), (s_r, f_r) = (load_run(tmp_path / d)
                                              for d in ("all", "every7", "resumed"))
    assert s_7["history_every"] == 7 and s_all["history_every"] == 1
    for s in (s_7, s_r):
        for key in ("max_penetration", "max_penetration_t", "max_penetration_at", "final"):
            assert s[key] == s_all[key], key
    assert all(np.array_equal(f_r[name], f_all[name]) for name in ("u", "zeta", "v"))
    assert s_all["max_penetration"] > 0


def test_contact_maximum_is_checkpointed():
    """The maximal interpenetration so far (value, time, place) goes into the checkpoint state
    and comes back on restore(), so a resumed run reports the maximum over the whole run."""
    from damage_dolfinx.catalogue import examples
    build = lambda: examples.get("3.3-ex3").build(  # noqa: E731
        MPI.COMM_WORLD, h=0.5, k=1e-5, T=1e-4, overrides={"stability_check": "off"})
    s = build()
    s.initialize()
    for _ in range(10):
        s.advance()
        s.track()
    worst = s.contact.summary()
    assert worst["max_penetration"] > 0 and worst["max_penetration_t"] > 0
    state = {name: (f.copy() if isinstance(f, np.ndarray) else f.x.array.copy())
             for name, f in s.checkpoint_state().items()}
    fresh = build()
    target = fresh.checkpoint_state()
    for name, f in target.items():
        (f if isinstance(f, np.ndarray) else f.x.array)[...] = state[name]
    fresh.restore(10)
    assert fresh.contact.summary() == worst and fresh.probe.first_zeta_star_time is None
