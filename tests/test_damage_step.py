"""The damage step: the PDE form (1.5) against manufactured solutions (L2 rates 2 in h, 1 in k),
and the obstacle form (SNES vinewtonrsls) against an independent primal-dual active-set solve."""
import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla
import ufl
from dolfinx import fem
from mpi4py import MPI

from damage_dolfinx import compat
from damage_dolfinx.numerics.damage import DamageStep
from damage_dolfinx.viz.post import loglog_rate
from damage_dolfinx.numerics.solvers import SolveContext

KAPPA = 0.1


def run_mms(msh, k, T, exact, source):
    """Integrate the PDE damage step with source(x, t_{n-1}); L2 error at T."""
    Z = compat.scalar_p1(msh)
    zeta, zeta_old = fem.Function(Z), fem.Function(Z)
    t_old = fem.Constant(msh, 0.0)
    x = ufl.SpatialCoordinate(msh)
    step = DamageStep(zeta, zeta_old, source(x, t_old), fem.Constant(msh, k),
                      fem.Constant(msh, KAPPA), SolveContext("mms"), obstacle=False,
                      prefix="mms_")
    zeta.interpolate(lambda X: exact(X, 0.0, np))
    for n in range(1, int(round(T / k)) + 1):
        zeta_old.x.array[:] = zeta.x.array
        t_old.value = (n - 1) * k
        step.solve()
    t_end = fem.Constant(msh, T)
    err = compat.assemble_scalar((zeta - exact(x, t_end, ufl)) ** 2 * ufl.dx(degree=6), msh.comm)
    return np.sqrt(err)


def c(x, lib):
    return lib.cos(np.pi * x[0]) * lib.cos(np.pi * x[1])  # satisfies d zeta/dn = 0 on the square


def test_pde_step_space_rate_is_two(unit_square):
    # zeta = 1 + 0.1 c(x) - 0.2 t: the explicit-source backward Euler step is exact in time here,
    # so the error is purely spatial.
    exact = lambda x, t, lib: 1 + 0.1 * c(x, lib) - 0.2 * t  # noqa: E731
    source = lambda x, t: -0.2 + KAPPA * 0.2 * np.pi**2 * c(x, ufl)  # noqa: E731
    hs, errs = [], []
    for n in (8, 16, 32, 64):
        errs.append(run_mms(unit_square(n), 0.05, 0.5, exact, source))
        hs.append(np.sqrt(2) / n)
    rate = loglog_rate(hs, errs)
    assert 1.85 < rate < 2.15, (errs, rate)


def test_pde_step_time_rate_is_one(unit_square):
    # zeta = 1 - 0.5 exp(-2t)(1 + 0.05 c(x)); fine mesh so the time error dominates
    exact = lambda x, t, lib: 1 - 0.5 * lib.exp(-2 * t) * (1 + 0.05 * c(x, lib))  # noqa: E731
    source = lambda x, t: ufl.exp(-2 * t) * (1 + 0.05 * c(x, ufl)) - \
        KAPPA * 0.05 * np.pi**2 * ufl.exp(-2 * t) * c(x, ufl)  # noqa: E731
    msh = unit_square(32)
    ks = [0.1, 0.05, 0.025, 0.0125]
    errs = [run_mms(msh, k, 1.0, exact, source) for k in ks]
    rate = loglog_rate(ks, errs)
    assert 0.9 < rate < 1.1, (errs, rate)


def pdas(A, b, lb, ub, tol=1e-13, max_it=100):
    """Primal-dual active set (Hintermueller-Ito-Kunisch) for min 1/2 z'Az - b'z, lb <= z <= ub."""
    c = A.diagonal().mean()
    z = np.clip(spla.spsolve(A.tocsc(), b), lb, ub)
    mu = b - A @ z
    for _ in range(max_it):
        upper = mu + c * (z - ub) > 0
        lower = mu + c * (z - lb) < 0
        free = ~(upper | lower)
        z_new = np.where(upper, ub, np.where(lower, lb, 0.0))
        rhs = b[free] - A[free][:, ~free] @ z_new[~free]
        z_new[free] = spla.spsolve(A[free][:, free].tocsc(), rhs)
        mu = b - A @ z_new
        mu[free] = 0.0
        if np.max(np.abs(z_new - z)) < tol:
            return z_new
        z = z_new
    raise RuntimeError("PDAS did not converge")


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="scipy reference is serial")
def test_obstacle_step_matches_active_set_reference(unit_square):
    msh = unit_square(24)
    Z = compat.scalar_p1(msh)
    zeta, zeta_old = fem.Function(Z), fem.Function(Z)
    zeta_old.interpolate(lambda X: 0.5 + 0.45 * np.sin(3 * X[0]) * np.cos(2 * X[1]))
    x = ufl.SpatialCoordinate(msh)
    # a source strong enough to push zeta through both bounds in one step
    phi = 60.0 * ufl.sin(2 * np.pi * x[0]) * ufl.cos(np.pi * x[1])
    k, zeta_star = 0.05, 0.01
    step = DamageStep(zeta, zeta_old, phi, fem.Constant(msh, k), fem.Constant(msh, 0.05),
                      SolveContext("vi-test"), obstacle=True, zeta_star=zeta_star, prefix="vitest_")
    its = step.solve()
    z = zeta.x.array.copy()
    # bounds at every dof
    assert z.min() >= zeta_star - 1e-14 and z.max() <= 1.0 + 1e-14
    n_lower, n_upper = np.sum(z <= zeta_star + 1e-12), np.sum(z >= 1 - 1e-12)
    assert n_lower > 10 and n_upper > 10, "the test must activate both bounds"
    # independent reference on the same discrete problem
    ai, aj, av = step.A.getValuesCSR()
    A = sp.csr_matrix((av, aj, ai), shape=step.A.getSize())
    b = step.b.getArray().copy()
    z_ref = pdas(A, b, zeta_star, 1.0)
    print(f"SNES-VI vs active set: max |dz| = {np.max(np.abs(z - z_ref)):.2e}, "
          f"{n_lower} dofs at zeta_star, {n_upper} at 1, {its} Newton iterations")
    assert np.max(np.abs(z - z_ref)) < 1e-8, np.max(np.abs(z - z_ref))
    # KKT: residual >= 0 on the lower set, <= 0 on the upper set, = 0 on the free set
    r = A @ z - b
    scale = np.abs(b).max()
    lower, upper = z <= zeta_star + 1e-12, z >= 1 - 1e-12
    free = ~(lower | upper)
    assert np.all(r[lower] >= -1e-10 * scale) and np.all(r[upper] <= 1e-10 * scale)
    assert np.max(np.abs(r[free])) < 1e-10 * scale
    assert 1 <= its <= 10
    # without the bounds the same step leaves [zeta_star, 1]: the obstacle really acts
    z_free = spla.spsolve(A.tocsc(), b)
    assert z_free.min() < zeta_star - 0.05 and z_free.max() > 1.05
