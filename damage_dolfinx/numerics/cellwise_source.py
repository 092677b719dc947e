"""The damage right-hand side by sparse maps when the source is constant on every cell.

l(xi) = (zeta_old, xi) + k (phi_old, xi) is assembled every step of the damage step (damage.py).
With variant A and lam_D = 0 (all of Section 3.3) the source is phi = -0.5 lam_u Psi_q(eps(u_old))
- lam_w, and for P1 displacements on simplices eps(u_old) is constant on each cell, so is phi, and

    l = M zeta_old + k Q phi_c,   phi_c = -0.5 lam_u min(|eps_c|^2, q_star) - lam_w,
    eps_c = G u_old (the cell strains, 4 or 9 components),

with M the P1 mass matrix, Q_ic = (1_c, xi_i) and G the map u -> cell strain, all three
assembled once by DOLFINx on the DG0 tensor space and cut to the components needed (G: the
d(d+1)/2 independent ones; Q: the first, one column per cell). Per step this is three sparse products and a few array operations instead of an
assembly with coefficient packing: 100 -> about 30 us on the wrench (980 zeta dofs). It is used
only after a check at set-up that it gives the assembled l to round-off on a random u_old.
"""
from __future__ import annotations

import numpy as np
import ufl
from petsc4py import PETSc

from damage_dolfinx import compat
from damage_dolfinx.numerics.constitutive import eps

#: largest relative difference to the assembled l accepted by the set-up check (round-off)
CHECK_RTOL = 1e-12


def assembled_matrix(a) -> PETSc.Mat:
    """The assembled matrix of the bilinear UFL form ``a`` (no boundary conditions)."""
    form = compat.form(a)
    A = compat.create_matrix(form)
    compat.assemble_matrix(A, form, [])
    A.assemble()
    return A


class CellwiseSource:
    """l = M zeta_old + k Q phi_c (module docstring) for ``u_old``, ``zeta_old``, k and the
    damage parameters ``p`` (variant A, lam_D = 0)."""

    def __init__(self, u_old, zeta_old, k: float, p):
        if p.variant != "A" or p.lam_D != 0.0:
            raise ValueError("the cellwise source needs variant A with lam_D = 0")
        msh = u_old.function_space.mesh
        d = msh.topology.dim
        Z, T = zeta_old.function_space, compat.tensor_dg0(msh)
        xi, tau = ufl.TestFunction(Z), ufl.TestFunction(T)
        self.M = assembled_matrix(ufl.TrialFunction(Z) * xi * ufl.dx)
        G = assembled_matrix(ufl.inner(eps(ufl.TrialFunction(u_old.function_space)), tau) * ufl.dx)
        volume = assembled_matrix(ufl.inner(ufl.TrialFunction(T), tau) * ufl.dx).getDiagonal()
        volume.reciprocal()
        G.diagonalScale(L=volume)  # rows / |c|: the cell strain itself
        # the independent strain components per cell, off-diagonal ones times sqrt(2), so that
        # |eps_c|^2 is the sum of their squares; Q on the first component of the DG0 tensor
        pairs = [(i, i) for i in range(d)] + [(i, j) for i in range(d) for j in range(i + 1, d)]
        start, end = G.getOwnershipRange()
        blocks = start + d * d * np.arange((end - start) // (d * d))
        rows = (blocks[:, None] + np.array([i * d + j for i, j in pairs])).ravel()
        comm = G.getComm()
        row_is = PETSc.IS().createGeneral(rows.astype(PETSc.IntType), comm=comm)
        u_cols = PETSc.IS().createStride(G.getOwnershipRangeColumn()[1]
                                         - G.getOwnershipRangeColumn()[0],
                                         G.getOwnershipRangeColumn()[0], 1, comm=comm)
        self.G = G.createSubMatrix(row_is, u_cols)
        weight = self.G.createVecLeft()
        weight.array.reshape(-1, len(pairs))[:] = [1.0 if i == j else np.sqrt(2.0) for i, j in pairs]
        self.G.diagonalScale(L=weight)
        Q = assembled_matrix(ufl.TrialFunction(T)[0, 0] * xi * ufl.dx)
        z_rows = PETSc.IS().createStride(Q.getOwnershipRange()[1] - Q.getOwnershipRange()[0],
                                         Q.getOwnershipRange()[0], 1, comm=comm)
        first = PETSc.IS().createGeneral(blocks.astype(PETSc.IntType), comm=comm)
        self.Q = Q.createSubMatrix(z_rows, first)
        self.components = len(pairs)
        self.u, self.zeta = compat.petsc_vec(u_old), compat.petsc_vec(zeta_old)
        self.e, self.phi = self.G.createVecLeft(), self.Q.createVecRight()
        self.q = self.Q.createVecLeft()
        self.k, self.p = float(k), p
        # views of the strains and the source (stable: the Vecs own their arrays)
        self._e = self.e.array.reshape(-1, self.components)
        self._e_sq = np.empty_like(self._e)
        self._phi, self._ones = self.phi.array, np.ones(self.components)

    def rhs(self, b: PETSc.Vec):
        """b = M zeta_old + k Q phi_c (owned entries; no ghost update is needed)."""
        p = self.p
        self.G.mult(self.u, self.e)
        e, phi = self._e, self._phi
        np.multiply(e, e, out=self._e_sq)  # |eps_c|^2: squares summed by a BLAS product
        np.dot(self._e_sq, self._ones, out=phi)  # (14 -> 7 us on the wrench)
        np.minimum(phi, p.q_star, out=phi)
        phi *= -0.5 * p.lam_u
        phi -= p.lam_w
        self.Q.mult(self.phi, self.q)
        self.M.mult(self.zeta, b)
        b.axpy(self.k, self.q)

    def check(self, L_form, u_old) -> float:
        """Relative difference to the assembled l on a random u_old (u_old is restored)."""
        saved = u_old.x.array.copy()
        rng = np.random.default_rng(0)
        u_old.x.array[:] = 1e-3 * rng.standard_normal(saved.shape)
        u_old.x.scatter_forward()  # ghosts = owners' values, as in a run
        assembled = compat.create_vector(L_form)
        with assembled.localForm() as bl:
            bl.set(0.0)
        compat.assemble_vector(assembled, L_form)
        assembled.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        mapped = assembled.duplicate()
        self.rhs(mapped)
        u_old.x.array[:] = saved
        mapped.axpy(-1.0, assembled)
        return mapped.norm() / max(assembled.norm(), 1e-300)
