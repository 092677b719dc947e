"""Cell-wise stresses by a sparse map instead of an interpolated fem.Expression.

For P1 displacements on simplices eps(u) is constant on each cell, so is B eps(u): the map
u -> (B eps(u))_c is a sparse matrix S, assembled once as (B eps(u), tau) over the DG0 tensor
space with its rows divided by |c|. Two steps interpolated such a quantity every step, which
costs DOLFINx's coefficient packing and a kernel call per cell (about 0.5-0.9 ms at 4k dofs):

* Section 2.4, (2.184): sigma_n = sigma_{n-1} + k B eps(w_n) + k Ghat_n (DG0 tensors):
  :class:`StressUpdate`, one product S w and two array updates;
* Section 2.3, (2.136): the memory integrand g = zeta Phi_L(B eps(u)) in the DG1 tensor space:
  :class:`MemoryIntegrand`, S u, the componentwise truncation Phi_L (clip to [-L, L], as
  constitutive.Phi_L) and the vertex values of zeta.

Each checks itself at construction against the interpolation it replaces, on a random state
(relative 1e-12), and raises otherwise; the caller then keeps the interpolation. The results
equal the interpolation to round-off (the summation order of B eps differs).
"""
from __future__ import annotations

import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

from damage_dolfinx import compat
from damage_dolfinx.numerics.cellwise_source import assembled_matrix
from damage_dolfinx.numerics.constitutive import B, eps

#: largest relative difference to the interpolation accepted by the set-up checks (round-off)
CHECK_RTOL = 1e-12


def stress_matrix(V, E, nu) -> PETSc.Mat:
    """S: u (P1 vector) -> B eps(u) on each cell, rows in the DG0 tensor dof layout."""
    T = compat.tensor_dg0(V.mesh)
    tau = ufl.TestFunction(T)
    S = assembled_matrix(ufl.inner(B(eps(ufl.TrialFunction(V)), E, nu), tau) * ufl.dx)
    inv = assembled_matrix(ufl.inner(ufl.TrialFunction(T), tau) * ufl.dx).getDiagonal()
    inv.reciprocal()
    S.diagonalScale(L=inv)  # rows / |c|: the cell value itself
    return S


def _check_against(target, expression, apply, randomize, funcs) -> float:
    """Largest relative difference, over the owned values of ``target``, between ``apply()``
    and compat.interpolate(target, expression) after ``randomize()`` has set a random state;
    the values of ``funcs`` (everything randomize or apply writes) are restored."""
    saved = [f.x.array.copy() for f in funcs]
    randomize()
    compat.interpolate(target, expression)
    V = target.function_space
    owned = V.dofmap.index_map.size_local * V.dofmap.index_map_bs
    expected = target.x.array[:owned].copy()
    apply()
    comm = V.mesh.comm
    diff = comm.allreduce(float(np.abs(target.x.array[:owned] - expected).max(initial=0.0)),
                          op=MPI.MAX)
    scale = comm.allreduce(float(np.abs(expected).max(initial=0.0)), op=MPI.MAX)
    for f, values in zip(funcs, saved):
        f.x.array[:] = values
    return diff / max(scale, 1e-300)


class StressUpdate:
    """sigma <- sigma_old + k (B eps(w) + Ghat) on the DG0 tensor space (2.184), by S w."""

    def __init__(self, sigma, sigma_old, w, G_hat, k: float, E, nu, expression):
        self.sigma, self.sigma_old, self.G_hat, self.k = sigma, sigma_old, G_hat, float(k)
        self.S = stress_matrix(w.function_space, E, nu)
        self.w = compat.petsc_vec(w)
        self.Sw = self.S.createVecLeft()
        self.owned = self.Sw.getLocalSize()  # owned DG0 tensor values
        self.check = self._check(w, expression)
        if not self.check <= CHECK_RTOL:
            raise RuntimeError(f"cell stress map differs from the interpolation by {self.check:.1e}")

    def __call__(self):
        n, k = self.owned, self.k
        self.S.mult(self.w, self.Sw)
        out = self.sigma.x.array
        np.add(self.Sw.array, self.G_hat.x.array[:n], out=out[:n])
        out[:n] *= k
        out[:n] += self.sigma_old.x.array[:n]
        self.sigma.x.scatter_forward()

    def _check(self, w, expression) -> float:
        """The map against the interpolation on random w, sigma_old, Ghat (all restored)."""
        def randomize():
            rng = np.random.default_rng(0)
            for f in (w, self.sigma_old, self.G_hat):
                f.x.array[:] = rng.standard_normal(f.x.array.size)
                f.x.scatter_forward()
        return _check_against(self.sigma, expression, self, randomize,
                              (w, self.sigma_old, self.G_hat, self.sigma))


class MemoryIntegrand:
    """g <- zeta Phi_L(B eps(u)) on the DG1 tensor space of the memory (2.136), by S u."""

    def __init__(self, g, u, zeta, E, nu, L_trunc, expression):
        self.g, self.u_fn, self.zeta = g, u, zeta
        V, Z, G = u.function_space, zeta.function_space, g.function_space
        self.S = stress_matrix(V, E, nu)
        self.u = compat.petsc_vec(u)
        self.Su = self.S.createVecLeft()
        self.L = None if L_trunc is None or np.isinf(L_trunc) else float(L_trunc)
        T = compat.tensor_dg0(V.mesh)
        self.comps = T.dofmap.index_map_bs  # d * d
        q = compat.cell_dofs(T)[:, 0]                   # the cell's DG0 tensor block
        zc = compat.cell_dofs(Z)                        # (cells, d + 1) vertex dofs of zeta
        gc = compat.cell_dofs(G)                        # (cells, d + 1) DG1 blocks
        if gc.shape != zc.shape or G.dofmap.index_map_bs != self.comps:
            raise RuntimeError("memory map: the memory space is not a DG1 tensor space")
        self._q, self._zc, self._gc = q, zc, gc.ravel()
        # the usual numbering (cell c holds DG0 block c and DG1 blocks 3c..3c+2): views and
        # products in place instead of gathers and a scatter
        self._q_identity = np.array_equal(q, np.arange(q.size))
        self._g_identity = np.array_equal(self._gc, np.arange(self._gc.size))
        self._z = np.empty(zc.shape)
        self.check = self._check(expression)
        if not self.check <= CHECK_RTOL:
            raise RuntimeError(f"memory map differs from the interpolation by {self.check:.1e}")

    def __call__(self):
        self.S.mult(self.u, self.Su)
        stress = self.Su.array.reshape(-1, self.comps)           # (cells, d * d)
        stress = stress[:self._q.size] if self._q_identity else stress[self._q]
        if self.L is not None:
            np.clip(stress, -self.L, self.L, out=stress)        # Phi_L (2.107)
        z = np.take(self.zeta.x.array, self._zc, out=self._z)    # (cells, d + 1)
        values = self.g.x.array.reshape(-1, self.comps)
        if self._g_identity:
            np.multiply(z[:, :, None], stress[:, None, :],
                        out=values[:self._gc.size].reshape(z.shape + (self.comps,)))
        else:
            values[self._gc] = (z[:, :, None] * stress[:, None, :]).reshape(-1, self.comps)
        self.g.x.scatter_forward()

    def _check(self, expression) -> float:
        """The map against the interpolation on random u and zeta, with the largest stress
        component at 2 L so that Phi_L clips (all restored)."""
        def randomize():
            rng = np.random.default_rng(0)
            self.u_fn.x.array[:] = rng.standard_normal(self.u_fn.x.array.size)
            self.u_fn.x.scatter_forward()
            if self.L is not None:
                self.S.mult(self.u, self.Su)
                top = self.g.function_space.mesh.comm.allreduce(
                    float(np.abs(self.Su.array).max(initial=0.0)), op=MPI.MAX)
                self.u_fn.x.array[:] *= 2.0 * self.L / max(top, 1e-300)
            self.zeta.x.array[:] = rng.uniform(0.01, 1.0, self.zeta.x.array.size)
            for f in (self.u_fn, self.zeta):
                f.x.scatter_forward()
        return _check_against(self.g, expression, self, randomize,
                              (self.u_fn, self.zeta, self.g))
