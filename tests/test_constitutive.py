"""Every constitutive piece against plain numpy on random tensors (truncations hit on purpose)."""
import numpy as np
import pytest
import ufl
from dolfinx import fem

from damage_dolfinx import compat
from damage_dolfinx.forms import constitutive as C
from damage_dolfinx.numerics import damage
from damage_dolfinx.core.parameters import ModelParameters

RNG = np.random.default_rng(2007)


def evaluate(msh, expr):
    """Value of a spatially constant UFL expression (evaluated at one cell)."""
    V = compat.scalar_dg0(msh)
    e = fem.Expression(expr, compat.interpolation_points(V))
    return compat.eval_expression(e, msh, [0]).reshape(-1)


def sym_tensors(count, scale):
    for _ in range(count):
        a = RNG.normal(scale=scale, size=(2, 2))
        yield 0.5 * (a + a.T)


def const(msh, value):
    return fem.Constant(msh, np.asarray(value, dtype=float))


def np_B(t, E, nu):
    return E * nu / (1 - nu**2) * np.trace(t) * np.eye(2) + E / (1 + nu) * t


def test_plane_stress_tensor(unit_square):
    msh = unit_square(1)
    E, nu = 5e9, 0.49
    for t in sym_tensors(5, 1e-3):
        got = evaluate(msh, ufl.as_vector([C.B_plane_stress(const(msh, t), E, nu)[i, j]
                                           for i in range(2) for j in range(2)]))
        assert np.allclose(got, np_B(t, E, nu).ravel(), rtol=1e-13, atol=0)
    # uniaxial plane stress: sigma_11 = E eps_11 when eps_22 = -nu eps_11
    t = np.array([[1e-3, 0.0], [0.0, -0.3e-3]])
    got = evaluate(msh, C.B_plane_stress(const(msh, t), 100.0, 0.3)[0, 0])
    assert got[0] == pytest.approx(0.1, rel=1e-12)
    assert evaluate(msh, C.B_plane_stress(const(msh, t), 100.0, 0.3)[1, 1])[0] == pytest.approx(0, abs=1e-15)


def test_truncation_phi_L(unit_square):
    msh = unit_square(1)
    for L in (0.5, 2.0):
        for t in sym_tensors(5, 1.5):
            got = evaluate(msh, ufl.as_vector([C.Phi_L(const(msh, t), L)[i, j]
                                               for i in range(2) for j in range(2)]))
            assert np.allclose(got, np.clip(t, -L, L).ravel(), rtol=0, atol=1e-15)
    assert C.Phi_L(const(msh, np.eye(2)), float("inf")) is not None  # identity for L = inf


@pytest.mark.parametrize("r", [-0.5, 0.0, 0.005, 0.3, 1.0, 1.7])
def test_eta_star(unit_square, r):
    msh = unit_square(1)
    got = evaluate(msh, C.eta_star(const(msh, r), 0.01))
    assert got[0] == pytest.approx(min(1.0, max(0.01, r)), abs=1e-15)


def np_split(e):
    lam = np.linalg.eigvalsh(e)
    return (np.maximum(lam, 0) ** 2).sum(), (np.minimum(lam, 0) ** 2).sum()


def test_tension_compression_split(unit_square):
    msh = unit_square(1)
    cases = list(sym_tensors(8, 1.0)) + [np.diag([2.0, -1.0]), np.diag([-3.0, -1.0]),
                                         np.diag([1.0, 1.0]), np.zeros((2, 2))]
    for e in cases:
        pos, neg = C.split_norms_sq(const(msh, e))
        got = evaluate(msh, ufl.as_vector([pos, neg]))
        want = np_split(e)
        assert np.allclose(got, want, rtol=1e-12, atol=1e-14), (e, got, want)
        assert got.sum() == pytest.approx((e * e).sum(), rel=1e-12, abs=1e-14)  # |e+|^2+|e-|^2 = |e|^2


def test_von_mises(unit_square):
    msh = unit_square(1)
    for s in sym_tensors(5, 100.0):
        want = np.sqrt(s[0, 0]**2 - s[0, 0] * s[1, 1] + s[1, 1]**2 + 3 * s[0, 1]**2)
        assert evaluate(msh, C.von_mises(const(msh, s)))[0] == pytest.approx(want, rel=1e-12)
    # pure shear tau: sqrt(3) tau
    assert evaluate(msh, C.von_mises(const(msh, [[0, 2.0], [2.0, 0]])))[0] == pytest.approx(2 * np.sqrt(3))


def test_sources_A_and_B(unit_square):
    msh = unit_square(1)
    p = ModelParameters(q_star=0.5, lam_D=0.1, lam_u=1000.0, lam_u_plus=300.0, lam_u_minus=70.0,
                        lam_w=0.2, zeta_star=0.01)
    for z in (0.001, 0.2, 0.9, 1.0, 1.3):
        for e in list(sym_tensors(3, 0.05)) + [np.diag([1.0, -0.2])]:  # last one caps Psi_q
            ez = min(1, max(0.01, z))
            pos, neg = np_split(e)
            wantA = 0.1 * (1 - ez) / ez - 0.5 * 1000.0 * min((e * e).sum(), 0.5) - 0.2
            wantB = 0.1 * (1 - z) / ez - 0.5 * 70.0 * min(neg, 0.5) - 0.5 * 300.0 * min(pos, 0.5) - 0.2
            gotA = evaluate(msh, damage.phi_A(const(msh, e), const(msh, z), p))[0]
            gotB = evaluate(msh, damage.phi_B(const(msh, e), const(msh, z), p))[0]
            assert gotA == pytest.approx(wantA, rel=1e-12, abs=1e-12)
            assert gotB == pytest.approx(wantB, rel=1e-12, abs=1e-12)
