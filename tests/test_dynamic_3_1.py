"""Section 3.1: discrete energy balance, the time-step limit of stability.py against measured
instability onsets, damage bounds, serial = mpirun -n 2, and damage softening the L-shape."""
import math

import numpy as np
import pytest
import ufl
from mpi4py import MPI

from conftest import load_run, run_cli, serial_and_two_ranks
from damage_dolfinx import compat
from damage_dolfinx.catalogue import examples
from damage_dolfinx.numerics import stability, stability_bound
from damage_dolfinx.numerics.boundary import clamped
from damage_dolfinx.forms.constitutive import B_plane_stress, eps
from damage_dolfinx.geometries import GAMMA_C, GAMMA_D, GAMMA_N
from damage_dolfinx.geometries.rectangle import rectangle, side
from damage_dolfinx.core.parameters import InputError
from damage_dolfinx.problem.problem import Problem
from damage_dolfinx.models.dynamic_3_1 import DynamicKelvinVoigt

COMM = MPI.COMM_WORLD


def free_square(k, T, traction=None, n=4):
    """3.1 Ex. 1 body and data without Gamma_C, with frozen damage (zeta = 1) and without
    truncation (L_trunc = inf): a linear problem."""
    params = examples.get("3.1-ex1").params.replace(damage_active=False, stability_check="off",
                                                    L_trunc=math.inf)
    geo = rectangle(COMM, (0, 0), (6, 6), n, n, {
        GAMMA_D: lambda x: side(0, 0.0)(x) | side(0, 6.0)(x), GAMMA_N: side(1, 6.0)})
    return DynamicKelvinVoigt(Problem("3.1", geo, T, k=k, params=params, name="3.1-free",
                                          traction=traction))


# ------------------------------------------------------------------ (a) energy balance
def energy_defect(k, T=0.5):
    """KE + elastic energy + viscous dissipation - work of the load at T, relative to the work.
    Discrete identity: defect = sum_n (|u_n - u_{n-1}|_B^2 - rho |v_n - v_{n-1}|^2)/2 = O(k)."""
    st = free_square(k, T, traction=lambda x, t: ufl.as_vector((20.0 * t, -20.0 * t)))
    ds = ufl.Measure("ds", domain=st.mesh, subdomain_data=st.data.geometry.facet_tags)
    E, nu, rho, m = st.params.E, st.params.nu, st.rho, st.m_visc
    _, f_N = st.loads()
    energy = lambda form: compat.assemble_scalar(compat.form(form), COMM)  # noqa: E731
    forms = {"kin": 0.5 * rho * ufl.inner(st.v, st.v) * ufl.dx,
             "el": 0.5 * ufl.inner(B_plane_stress(eps(st.u), E, nu), eps(st.u)) * ufl.dx,
             "diss": k * ufl.inner(B_plane_stress(eps(st.v), E, nu) / m, eps(st.v)) * ufl.dx,
             "work": k * ufl.inner(f_N, st.v) * ds(GAMMA_N)}
    forms = {key: compat.form(f) for key, f in forms.items()}
    st.initialize()
    diss = work = 0.0
    while st.n < st.num_steps:
        st.advance()
        diss += energy(forms["diss"])
        work += energy(forms["work"])
    total = energy(forms["kin"]) + energy(forms["el"]) + diss
    return (total - work) / work


def test_energy_balance_first_order():
    d = [energy_defect(k) for k in (0.01, 0.005, 0.0025)]
    print("relative energy defects", d)
    assert all(abs(x) < 0.05 for x in d)
    for coarse, fine in zip(d, d[1:]):
        assert 1.7 < coarse / fine < 2.3  # O(k)


# ------------------------------------------------------------------ (b) stability helper
def test_closed_forms():
    assert stability.critical_time_step(0.0, 10.0) == math.inf
    assert stability.critical_time_step(4.0, math.inf) == pytest.approx(1.0)
    assert stability.critical_time_step(1e12, 100.0) == pytest.approx(0.02, rel=1e-6)
    assert stability.check_time_step(0.01, 0.02, "test") == pytest.approx(0.5)
    with pytest.raises(InputError, match="k_max"):
        stability.check_time_step(0.03, 0.02, "test", action="error")


@pytest.mark.parametrize("method", ["power", "slepc"])
def test_largest_eigenvalue_ignores_dirichlet_rows(method):
    """E = 100, rho = 2700: omega^2_max << 1, so the unit Dirichlet diagonals of K and M must
    not show up; compared with a dense solve on the free dofs."""
    if method == "slepc" and stability._slepc() is None:
        pytest.skip("slepc4py not importable")
    if COMM.size > 1:
        pytest.skip("dense check is serial")
    geo = rectangle(COMM, (0, 0), (6, 6), 4, 4, {GAMMA_D: side(0, 0.0)})
    V = compat.vector_p1(geo.mesh)
    bcs = [clamped(V, geo.facet_tags, GAMMA_D)]
    K, _, M = stability.stiffness_and_mass(V, 100.0, 0.3, 2700.0, bcs=bcs)
    lam = stability.largest_eigenvalue(K, M, tol=1e-10, max_it=5000, method=method)
    import scipy.linalg
    Kd, Md = K.convert("dense").getDenseArray(), M.convert("dense").getDenseArray()
    free = np.flatnonzero(np.abs(Kd - np.diag(np.diag(Kd))).sum(axis=1) > 0)
    exact = scipy.linalg.eigh(Kd[np.ix_(free, free)], Md[np.ix_(free, free)], eigvals_only=True)[-1]
    print(method, lam, exact)
    assert exact < 0.5
    assert lam == pytest.approx(exact, rel=1e-4)


def free_vibration_growth(f, steps=200):
    """||v_N|| / ||v_0|| of a free (unloaded) vibration from a rough initial velocity at
    k = f k_max (no contact: linear, the growth is exponential beyond k_max)."""
    probe = free_square(0.01, 0.01)
    V = probe.v.function_space
    k_max = stability.estimate_k_max(V, probe.params.E, probe.params.nu, probe.rho,
                                     probe.m_visc, bcs=probe.bcs)
    k = f * k_max
    st = free_square(k, steps * k)
    st.initialize()
    X = V.tabulate_dof_coordinates()
    st.v.x.array[:] = np.stack([np.sin(3.1 * X[:, 0] + 1.7 * X[:, 1]),
                                np.cos(5.3 * X[:, 1] - 2.3 * X[:, 0])], axis=1).reshape(-1)
    v0 = st.scalars()["v_L2"]
    while st.n < st.num_steps:
        st.advance()
    return st.scalars()["v_L2"] / v0, k_max


def test_k_max_matches_measured_onset_without_contact():
    growth = {f: free_vibration_growth(f)[0] for f in (0.8, 0.9, 1.1, 1.2)}
    print("growth of ||v|| over 200 steps at k/k_max:", growth)
    assert growth[0.8] < 1.0 and growth[0.9] < 1.0      # stable: decays
    assert growth[1.1] > 1e3 and growth[1.2] > 1e3      # unstable: orders of magnitude


def contact_oscillation(f):
    """G23 case (3.1 Ex. 1, n = 4, damage frozen): max |second difference of ||v_n|| in time|
    relative to max ||v_n|| at k = f k_max; the explicit contact chatters beyond k_max. Literal
    reading: c_nu = 1/mu = 2e4 (the evidence reading's c_nu = 5e-5 has no contact limit)."""
    ex = examples.get("3.1-ex1", "literal")
    with stability_bound.exact_estimates():  # k = 1e-3 alone is decided by the bound
        k_max = ex.build(COMM, n=4, k=1e-3, T=1e-3).stability["k_max"]
    N = int(round(1.0 / (f * k_max)))
    st = ex.build(COMM, n=4, k=1.0 / N, T=1.0,
                  overrides={"damage_active": False, "stability_check": "off"})
    st.initialize()
    v = []
    while st.n < st.num_steps:
        st.advance()
        v.append(st.scalars()["v_L2"])
    v = np.array(v)
    return float(np.abs(np.diff(v, 2)).max() / v.max()), k_max


def test_k_max_with_contact_matches_measured_onset():
    osc = {f: contact_oscillation(f)[0] for f in (0.8, 0.9, 1.1, 1.2)}
    k_max = contact_oscillation(0.5)[1]
    print(f"k_max = {k_max:.4g}; oscillation indicator at k/k_max:", osc)
    assert 0.01 < k_max < 0.02  # G23: 0.01 smooth, 0.05 oscillates
    assert osc[0.8] < 0.03 and osc[0.9] < 0.03
    assert osc[1.1] > 0.08 and osc[1.2] > 0.08


def test_stability_check_error_from_cli(tmp_path):
    proc = run_cli(["run", "3.1-ex1", "--n", "4", "--k", "0.05", "--T", "0.1", "--quiet",
                    "--reading", "literal", "--set", "stability_check=error", "--out", tmp_path],
                   check=False)
    assert proc.returncode == 2 and "exceeds the stability limit" in proc.stderr


# ------------------------------------------------------------------ (c) damage bounds
def test_damage_stays_in_bounds(tmp_path):
    run_cli(["run", "3.1-ex1", "--n", "4", "--k", "0.01", "--T", "0.3", "--quiet",
             "--no-figures", "--set", "lam_u=1e7", "--out", tmp_path])
    summary, fields = load_run(tmp_path)
    z = fields["zeta"]
    print("zeta range", z.min(), z.max())
    assert z.min() >= 0.01 - 1e-10 and z.max() <= 1.0 + 1e-10
    assert z.min() == pytest.approx(0.01, abs=1e-8)   # the lower bound is active
    assert summary["k_over_k_max"] < 1.0 and "k_max" in summary


# ------------------------------------------------------------------ (d) serial = 2 ranks
@pytest.mark.mpi
@pytest.mark.parametrize("args", [
    ["run", "3.1-ex1", "--n", "8", "--k", "0.01", "--T", "0.2"],
    ["run", "3.1-ex3", "--h", "0.25", "--k", "0.001", "--T", "0.1"]])
def test_serial_equals_two_ranks(tmp_path, args):
    serial_and_two_ranks(tmp_path, args + ["--no-figures", "--quiet"])


# ------------------------------------------------------------------ (e) L-shape
def test_damage_softens_lshape(tmp_path):
    """Figure 3.7: the damaged body deforms more; with the nearly uniform damage that kappa = 1
    produces, by about 1/zeta - 1 (quasistatic response, stiffness zeta B)."""
    out = {}
    for active in (0, 1):
        run_cli(["run", "3.1-ex3", "--h", "0.25", "--k", "0.001", "--T", "1.5", "--quiet",
                 "--no-figures", "--set", f"damage_active={active}", "--out", tmp_path / str(active)])
        out[active] = load_run(tmp_path / str(active))[0]["final"]
    increase = out[1]["u_max"] / out[0]["u_max"] - 1.0
    expected = 1.0 / out[1]["zeta_mean"] - 1.0
    print(f"max |u|: undamaged {out[0]['u_max']:.6e}, damaged {out[1]['u_max']:.6e}, "
          f"increase {100 * increase:.4f} % (1/zeta_mean - 1 = {100 * expected:.4f} %)")
    assert out[0]["zeta_min"] == 1.0 and out[1]["zeta_max"] < 1.0
    assert increase > 0.0
    assert 0.3 * expected < increase < 3.0 * expected


def test_power_iteration_agrees_with_slepc_with_contact():
    """The fallback (power iteration, one factorisation) gives the k_max of the SLEPc path."""
    if stability._slepc() is None:
        pytest.skip("slepc4py not importable")
    st = examples.get("3.1-ex1", "literal").build(COMM, n=8, k=0.01, T=0.01,
                                                  overrides={"stability_check": "off"})
    ds = ufl.Measure("ds", domain=st.mesh, subdomain_data=st.data.geometry.facet_tags)
    args = (st.v.function_space, st.params.E, st.params.nu, st.rho, st.m_visc, st.c_nu,
            ds(GAMMA_C), st.bcs)
    power = stability.estimate_stability(*args, method="power")
    slepc = stability.estimate_stability(*args, method="slepc")
    print(power, slepc)
    assert power["k_max"] == pytest.approx(slepc["k_max"], rel=2e-3)
    assert power["omega2_max"] == pytest.approx(slepc["omega2_max"], rel=2e-3)


# ------------------------------------------------------------------ (f) the step's scalars
def test_scalars_equal_assembled_norms():
    """history.csv's ||u||_L2 (M u_n carried by (3.51) from step to step), ||eps(u)||_L2, ||v||_L2
    and max |u| equal the assembled integrals and the nodal maximum, also after a step without
    scalars (a history cadence > 1) and after restore."""
    st = free_square(0.01, 0.05, traction=lambda x, t: ufl.as_vector((20.0 * t, -20.0 * t)))
    norm = lambda f: math.sqrt(compat.assemble_scalar(compat.form(f * ufl.dx), COMM))  # noqa: E731
    st.initialize()
    st.scalars()
    for skip in (False, False, True, False, False):
        st.advance()
        if skip:
            continue
        s = st.scalars()
        assert s["u_L2"] == pytest.approx(norm(ufl.inner(st.u, st.u)), rel=1e-12)
        assert s["eps_u_L2"] == pytest.approx(norm(ufl.inner(eps(st.u), eps(st.u))), rel=1e-12)
        assert s["v_L2"] == pytest.approx(norm(ufl.inner(st.v, st.v)), rel=1e-12)
        nodes = np.linalg.norm(st.u.x.array.reshape(-1, 2), axis=1).max()
        assert s["u_max"] == pytest.approx(COMM.allreduce(nodes, op=MPI.MAX), rel=1e-14)
    st.u.x.array[:] *= 2.0  # a loaded state: M u from u itself
    st.restore(st.n)
    assert st.scalars()["u_L2"] == pytest.approx(norm(ufl.inner(st.u, st.u)), rel=1e-12)


def test_elastic_term_one_point_rule_exact():
    """(zeta Phi_L(B eps(u)), eps(w)) with P1 u, zeta on triangles: the one-point rule the
    velocity step uses equals degree 4 to round-off, with the truncation active on some cells;
    a quadrilateral mesh keeps NONLINEAR_DEGREE."""
    from dolfinx import fem, mesh as dmesh
    from damage_dolfinx.forms import dynamic_kelvin_voigt as dkv
    from damage_dolfinx.forms.kelvin_voigt import damaged_elastic_stress
    msh = dmesh.create_unit_square(COMM, 6, 5)
    V, Z = compat.vector_p1(msh), compat.scalar_p1(msh)
    u, zeta = fem.Function(V), fem.Function(Z)
    u.interpolate(lambda x: np.vstack((np.sin(3 * x[0]) * x[1], x[0] ** 2 - np.cos(2 * x[1]))))
    zeta.interpolate(lambda x: 0.2 + 0.7 * x[0] * x[1])
    assert dkv.elastic_degree(u, zeta) == 1
    w = ufl.TestFunction(V)
    term = ufl.inner(damaged_elastic_stress(u, zeta, 1e4, 0.3, 3000.0), eps(w))  # Phi_L clips
    from petsc4py import PETSc
    vectors = []
    for degree in (1, 4):
        L = compat.form(term * ufl.dx(metadata={"quadrature_degree": degree}))
        b = compat.create_vector(L)
        compat.assemble_vector(b, L)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        vectors.append(b.array.copy())
    assert np.abs(vectors[0] - vectors[1]).max() <= 1e-12 * np.abs(vectors[1]).max()
    quads = dmesh.create_unit_square(COMM, 2, 2, dmesh.CellType.quadrilateral)
    Vq, Zq = compat.vector_p1(quads), compat.scalar_p1(quads)
    assert dkv.elastic_degree(fem.Function(Vq), fem.Function(Zq)) == dkv.NONLINEAR_DEGREE
    assert compat.dirichlet_values_zero([clamped(V, dmesh.meshtags(msh, 1, np.zeros(0, np.int32),
                                                                   np.zeros(0, np.int32)), 1)])
    assert not compat.dirichlet_values_zero([fem.dirichletbc(np.array([0.0, 1.0]),
                                                             np.array([0], np.int32), V)])
