"""Issue 17, 3-D: constitutive pieces against numpy, the 2-D results unchanged (against runs
recorded before any 3-D change), and physics checks of the 3-D Section 2.1 model. Small meshes:
every test takes seconds."""
import json
import sys
from pathlib import Path

import numpy as np
import pytest
import ufl
from dolfinx import fem
from mpi4py import MPI

from damage_dolfinx import compat, constitutive as C

HERE = Path(__file__).parent
RNG = np.random.default_rng(17)


@pytest.fixture(scope="module")
def cube():
    return compat.create_box(MPI.COMM_SELF, (0, 0, 0), (1, 1, 1), (1, 1, 1))


def evaluate(msh, expr):
    """Value of a spatially constant UFL expression (evaluated at one cell)."""
    V = compat.scalar_dg0(msh)
    e = fem.Expression(expr, compat.interpolation_points(V))
    return compat.eval_expression(e, msh, [0]).reshape(-1)


def const(msh, value):
    return fem.Constant(msh, np.asarray(value, dtype=float))


def flat(t, d=3):
    return ufl.as_vector([t[i, j] for i in range(d) for j in range(d)])


def sym3(scale):
    a = RNG.normal(scale=scale, size=(3, 3))
    return 0.5 * (a + a.T)


def with_eigenvalues(ls):
    """A symmetric tensor with the given eigenvalues and a random orthonormal frame."""
    Q, _ = np.linalg.qr(RNG.normal(size=(3, 3)))
    return Q @ np.diag(ls) @ Q.T


def np_split(t):
    ls = np.linalg.eigvalsh(t)
    return float(np.sum(np.maximum(ls, 0) ** 2)), float(np.sum(np.minimum(ls, 0) ** 2))


def test_isotropic_elasticity(cube):
    E, nu = 1e4, 0.33
    lmbda, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    for _ in range(4):
        t = sym3(1e-3)
        got = evaluate(cube, flat(C.B(const(cube, t), E, nu)))
        assert np.allclose(got, (lmbda * np.trace(t) * np.eye(3) + 2 * mu * t).ravel(),
                           rtol=1e-13, atol=1e-18)
    # plane-stress reduction: with eps_33 = -nu/(1-nu)(eps_11 + eps_22), sigma_33 = 0 and the
    # in-plane block is B_plane_stress (2.36) of the in-plane strain
    t2 = sym3(1e-3)[:2, :2]
    t = np.zeros((3, 3))
    t[:2, :2] = t2
    t[2, 2] = -nu / (1 - nu) * np.trace(t2)
    s3 = evaluate(cube, flat(C.B(const(cube, t), E, nu))).reshape(3, 3)
    s2 = E * nu / (1 - nu**2) * np.trace(t2) * np.eye(2) + E / (1 + nu) * t2
    assert abs(s3[2, 2]) < 1e-12 * np.abs(s2).max()
    assert np.allclose(s3[:2, :2], s2, rtol=1e-12, atol=1e-12 * np.abs(s2).max())


def test_phi_L_3x3(cube):
    for L in (0.5, 2.0):
        t = sym3(1.5)
        got = evaluate(cube, flat(C.Phi_L(const(cube, t), L)))
        assert np.allclose(got, np.clip(t, -L, L).ravel(), rtol=0, atol=1e-15)


@pytest.mark.parametrize("case", ["random", "two_equal", "three_equal", "zero_pair", "zero",
                                  "uniaxial_stress", "tiny"])
def test_split_3x3_against_eigvalsh(cube, case):
    """|eps^+|^2, |eps^-|^2 of the closed-form eigenvalues equal numpy's eigvalsh, also for
    repeated eigenvalues (the delicate case of the trigonometric formula)."""
    tensors = {"random": [sym3(1e-2) for _ in range(6)],
               "two_equal": [with_eigenvalues([3e-3, -1e-3, -1e-3]),
                             with_eigenvalues([2e-3, 2e-3, -5e-4])],
               "three_equal": [2e-3 * np.eye(3), -1e-3 * np.eye(3)],
               "zero_pair": [np.diag([1e-3, 0.0, 0.0]), with_eigenvalues([0.0, 0.0, -4e-3])],
               "zero": [np.zeros((3, 3))],
               "uniaxial_stress": [np.diag([1e-3, -0.33e-3, -0.33e-3])],
               "tiny": [sym3(1e-9)]}[case]
    for t in tensors:
        pos, neg = C.split_norms_sq(const(cube, t))
        got = evaluate(cube, ufl.as_vector([pos, neg]))
        want = np.array(np_split(t))
        scale = max(float(np.sum(t * t)), 1e-300)
        assert np.all(np.abs(got - want) <= 1e-12 * scale + 1e-29), (t, got, want)
    if case == "zero":  # the regulariser leaves (numerically) nothing
        assert np.all(np.abs(got) < 1e-28)


def test_von_mises_3x3(cube):
    for _ in range(3):
        s = sym3(100.0)
        d = s - np.trace(s) / 3 * np.eye(3)
        got = evaluate(cube, C.von_mises(const(cube, s)))[0]
        assert got == pytest.approx(np.sqrt(1.5 * np.sum(d * d)), rel=1e-13)
    # plane stress (s_i3 = 0): the 3-D value equals the 2-D formula of PROBLEMS.md 1.9
    s = np.zeros((3, 3))
    s[:2, :2] = sym3(100.0)[:2, :2]
    got = evaluate(cube, C.von_mises(const(cube, s)))[0]
    s11, s22, s12 = s[0, 0], s[1, 1], s[0, 1]
    assert got == pytest.approx(np.sqrt(s11**2 - s11 * s22 + s22**2 + 3 * s12**2), rel=1e-13)


def test_2d_runs_unchanged(tmp_path):
    """The fixed small 2-D runs of benchmarks/threed_2d_reference.py (2.1-ex1 n = 10, k = 0.05,
    T = 1; 2.2-ex1 n = 8, T = 0.2) equal the runs recorded before any issue-17 change (commit
    549c1d6, tests/data/reference_2d.json) to round-off: history scalars at every step and
    final nodal fields."""
    sys.path.insert(0, str(HERE.parent / "benchmarks"))
    from threed_2d_reference import CASES, REFERENCE, compare, run_case
    ref = json.loads(REFERENCE.read_text())
    for ex, args in CASES.items():
        diffs = compare(run_case(ex, args, tmp_path / ex), ref["runs"][ex])
        print(ex, f"largest relative difference {max(diffs.values()):.2e}")
        for key, value in diffs.items():
            assert value <= 1e-10, (ex, key, value)
