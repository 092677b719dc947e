"""Cell-wise stress maps (cellwise_stress.py): equal to the interpolation they replace
on random states, truncation included, in 2-D and 3-D; a map that differs is refused."""
import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI

from damage_dolfinx import compat
from damage_dolfinx.numerics.cellwise_stress import MemoryIntegrand, StressUpdate
from damage_dolfinx.numerics.constitutive import B, Phi_L, eps
from forms.viscoplastic import stress_update

E, NU = 100.0, 0.3


def unit_mesh(dim):
    comm = MPI.COMM_WORLD
    if dim == 2:
        return mesh.create_unit_square(comm, 6, 5)
    return mesh.create_unit_cube(comm, 3, 3, 2)


@pytest.mark.parametrize("dim", [2, 3])
def test_memory_integrand_equals_interpolation(dim):
    msh = unit_mesh(dim)
    V, Z = compat.vector_p1(msh), compat.scalar_p1(msh)
    G = compat.function_space(msh, "DG", 1, (dim, dim))
    u, zeta, g = fem.Function(V), fem.Function(Z), fem.Function(G)
    L = 1000.0
    expr = compat.expression(zeta * Phi_L(B(eps(u), E, NU), L), G)
    m = MemoryIntegrand(g, u, zeta, E, NU, L, expr)
    assert m.check <= 1e-12
    # an independent state: half the stress components beyond L, so Phi_L clips
    rng = np.random.default_rng(1)
    u.x.array[:] = rng.standard_normal(u.x.array.size)
    u.x.scatter_forward()
    m.S.mult(m.u, m.Su)
    top = msh.comm.allreduce(float(np.abs(m.Su.array).max(initial=0.0)), op=MPI.MAX)
    u.x.array[:] *= 3.0 * L / top
    zeta.x.array[:] = rng.uniform(0.01, 1.0, zeta.x.array.size)
    m.S.mult(m.u, m.Su)
    clipped = msh.comm.allreduce(int(np.sum(np.abs(m.Su.array) > L)), op=MPI.SUM)
    assert clipped > 0
    compat.interpolate(g, expr)
    expected = g.x.array.copy()
    g.x.array[:] = 0.0
    m()
    assert np.abs(g.x.array - expected).max() <= 1e-12 * np.abs(expected).max()


@pytest.mark.parametrize("dim", [2, 3])
def test_stress_update_equals_interpolation(dim):
    msh = unit_mesh(dim)
    V, Q = compat.vector_p1(msh), compat.tensor_dg0(msh)
    w = fem.Function(V)
    sigma, sigma_old, G_hat = (fem.Function(Q) for _ in range(3))
    k = 0.01
    expr = compat.expression(stress_update(sigma_old, w, G_hat, fem.Constant(msh, k), E, NU), Q)
    m = StressUpdate(sigma, sigma_old, w, G_hat, k, E, NU, expr)
    assert m.check <= 1e-12
    rng = np.random.default_rng(2)
    for f in (w, sigma_old, G_hat):
        f.x.array[:] = rng.standard_normal(f.x.array.size)
        f.x.scatter_forward()
    compat.interpolate(sigma, expr)
    expected = sigma.x.array.copy()
    sigma.x.array[:] = 0.0
    m()
    assert np.abs(sigma.x.array - expected).max() <= 1e-12 * np.abs(expected).max()


def test_a_map_that_differs_is_refused():
    msh = unit_mesh(2)
    V, Q = compat.vector_p1(msh), compat.tensor_dg0(msh)
    w = fem.Function(V)
    sigma, sigma_old, G_hat = (fem.Function(Q) for _ in range(3))
    other = compat.expression(stress_update(sigma_old, w, G_hat, fem.Constant(msh, 0.01),
                                            2 * E, NU), Q)  # another Young's modulus
    with pytest.raises(RuntimeError, match="differs from the interpolation"):
        StressUpdate(sigma, sigma_old, w, G_hat, 0.01, E, NU, other)
    G = compat.function_space(msh, "DG", 1, (2, 2))
    u, zeta, g = fem.Function(V), fem.Function(compat.scalar_p1(msh)), fem.Function(G)
    untruncated = compat.expression(zeta * B(eps(u), E, NU), G)  # the map truncates at 1000
    with pytest.raises(RuntimeError, match="differs from the interpolation"):
        MemoryIntegrand(g, u, zeta, E, NU, 1000.0, untruncated)
