"""Matrices whose entries are linear in the nodal damage zeta, updated by a precomputed sparse map
instead of a re-assembly (issue 18): ZetaLinearMatrix, and VelocitySolver, the LinearSolver of the
velocity step (3.159) of Section 3.3 built on it. Serial only (see ZetaLinearMatrix)."""
from __future__ import annotations

import time

import numpy as np
from dolfinx import fem
from petsc4py import PETSc

from . import compat
from .solvers import LinearSolver


class ZetaLinearMatrix:
    """The matrix of (3.159), A(zeta) = A_0 + sum_j zeta_j W_j (A_0 = rho/k M with the Dirichlet
    rows, W_j = a_visc(phi_j) linear in zeta), as CSR values data_0 + G zeta: one sparse product
    per step instead of a re-assembly (issue 18). G is built once from a few assemblies: the
    zeta dofs get a distance-2 colouring, so each entry (p, q) of a_visc(indicator of a colour)
    comes from the single dof of that colour in the closed neighbourhood of p. Serial only (in
    parallel, rows owned here may get contributions from dofs this rank does not hold)."""

    def __init__(self, A, V, a_mass, a_visc, zeta, bcs):
        import scipy.sparse as sp
        Z = zeta.function_space
        bs = V.dofmap.index_map_bs
        compat.assemble_matrix(A, compat.form(a_mass), bcs)             # rho/k M, bc rows
        A.assemble()
        self.indptr, self.indices, self.data0 = (a.copy() for a in A.getValuesCSR())
        rows = np.repeat(np.arange(self.indptr.size - 1), np.diff(self.indptr))
        cz, cv = compat.cell_dofs(Z), compat.cell_dofs(V)
        z_of_v = np.empty(V.dofmap.index_map.size_local + V.dofmap.index_map.num_ghosts, int)
        z_of_v[cv.ravel()] = cz.ravel()                                 # P1: same vertex order
        nz = zeta.x.array.size
        cells = sp.csr_matrix((np.ones(cz.size), (np.repeat(np.arange(cz.shape[0]), cz.shape[1]),
                                                  cz.ravel())), shape=(cz.shape[0], nz))
        adj = (cells.T @ cells).tocsr()                                 # closed neighbourhoods
        adj2 = (adj @ adj).tocsr()
        colour = np.full(nz, -1)
        for j in range(nz):                                             # greedy, distance 2
            used, c = set(colour[adj2.indices[adj2.indptr[j]:adj2.indptr[j + 1]]].tolist()), 0
            while c in used:
                c += 1
            colour[j] = c
        ncol = colour.max() + 1
        near = np.full((nz, ncol), -1)                                  # dof of colour c next to p
        coo = adj.tocoo()
        near[coo.row, colour[coo.col]] = coo.col
        bc_dofs = np.zeros(self.indptr.size - 1, bool)
        for bc in bcs:
            bc_dofs[compat.bc_dofs(bc)] = True
        keep = ~(bc_dofs[rows] | bc_dofs[self.indices])
        z_row = z_of_v[rows // bs]
        ind = fem.Function(Z)
        a_ind = compat.form(a_visc(ind))
        W = compat.create_matrix(a_ind)
        G_rows, G_cols, G_vals = [], [], []
        for c in range(ncol):
            ind.x.array[:] = colour == c
            W.zeroEntries()
            compat.assemble_matrix(W, a_ind, [])
            W.assemble()
            ip, ix, val = W.getValuesCSR()
            j = near[z_row, c]
            if not (np.array_equal(ip, self.indptr) and np.array_equal(ix, self.indices)) or \
                    np.any((val != 0) & (j < 0)):
                raise RuntimeError("velocity matrix map: sparsity or colouring mismatch")
            sel = keep & (j >= 0) & (val != 0)
            G_rows.append(np.flatnonzero(sel)), G_cols.append(j[sel]), G_vals.append(val[sel])
        W.destroy()
        self.G = sp.csr_matrix((np.concatenate(G_vals), (np.concatenate(G_rows),
                                                         np.concatenate(G_cols))),
                               shape=(self.data0.size, nz))
        self.colours, self._last = int(ncol), None
        self._previous = (None, None)  # (zeta, G zeta) of the update before the last
        # the PETSc matrix shares its CSR value array: the update writes it in place
        self.data = self.data0.copy()
        self.mat = PETSc.Mat().createAIJWithArrays(A.getSize(), (self.indptr, self.indices,
                                                                 self.data), comm=A.getComm())

    def product(self, zeta_values):
        """G zeta, reused from the last two updates where zeta is theirs (the right-hand side
        of step n needs G zeta_{n-1}, which the matrix update of step n-1 computed)."""
        for last, Gz in ((self._last, getattr(self, "Gz", None)), self._previous):
            if last is not None and np.array_equal(zeta_values, last):
                return Gz
        return self.G @ zeta_values

    def update(self, zeta_values) -> bool:
        """A(zeta) into ``self.mat``; False (unchanged) when zeta is the one of the last update."""
        if self._last is not None and np.array_equal(zeta_values, self._last):
            return False
        self._previous = (self._last, getattr(self, "Gz", None))
        self._last = zeta_values.copy()
        self.Gz = self.G @ zeta_values
        np.add(self.data0, self.Gz, out=self.data)
        self.mat.assemble()  # new object state: the preconditioner is rebuilt
        return True


class VelocitySolver(LinearSolver):
    """LinearSolver of (3.159) whose matrix comes from ZetaLinearMatrix (serial). With ``rhs`` =
    (l_boundary, v_old, u_old, zeta_old, m_visc) (only for Phi_L = identity and homogeneous
    Dirichlet data) the right-hand side is rho/k M v_{n-1} - m_visc a_visc(zeta_{n-1}) u_{n-1}
    (two products with the same maps) plus the assembled boundary terms."""

    def __init__(self, a, l, bcs, prefix, context, V, a_mass, a_visc, zeta, rhs=None, defaults=None):
        super().__init__(a, l, bcs, prefix, context, constant_matrix=False,
                         defaults=defaults)
        self.zeta = zeta
        self.fast = f = ZetaLinearMatrix(self.A, V, a_mass, a_visc, zeta, self.bcs)
        self.A.destroy()
        self.A = f.mat
        self.ksp.setOperators(self.A)
        self.rhs = rhs
        if rhs is not None:
            self.l_boundary = compat.form(rhs[0])
            self._el_data, self._el_zeta = np.zeros_like(f.data0), None
            self.M, self.K = (PETSc.Mat().createAIJWithArrays(self.A.getSize(), (
                f.indptr, f.indices, data), comm=self.A.getComm()) for data in (f.data0,
                                                                               self._el_data))
            self._tmp = self.b.duplicate()
            self._tmp.set(1.0)  # homogeneous Dirichlet data (clamped): the lifting adds 0
            compat.set_bc(self._tmp, self.bcs)
            bc = np.concatenate([compat.bc_dofs(c) for c in self.bcs] + [np.zeros(0, int)])
            self._lifting = bool(np.any(self._tmp.array[bc] != 0.0))

    def assemble_rhs(self):
        if self.rhs is None:
            return super().assemble_rhs()
        start = time.perf_counter()
        _, v_old, u_old, zeta_old, m_visc = self.rhs
        z, f = zeta_old.x.array, self.fast
        if self._el_zeta is None or not np.array_equal(z, self._el_zeta):
            self._el_zeta = z.copy()
            Gz = f.product(z)
            np.multiply(Gz, m_visc, out=self._el_data)                  # K_B(zeta_{n-1})
            self.K.assemble()
        with self.b.localForm() as bl:
            bl.set(0.0)
        compat.assemble_vector(self.b, self.l_boundary)                 # contact + load
        self.M.mult(compat.petsc_vec(v_old), self._tmp)                 # rho/k M v_{n-1}
        self.b.axpy(1.0, self._tmp)
        self.K.mult(compat.petsc_vec(u_old), self._tmp)                 # K_B(zeta_{n-1}) u_{n-1}
        self.b.axpy(-1.0, self._tmp)
        if self._lifting:
            compat.apply_lifting(self.b, self.a, self.bcs)
        self.b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        compat.set_bc(self.b, self.bcs)
        self.timings["assemble_rhs"] += time.perf_counter() - start

    def assemble_matrix(self):
        start = time.perf_counter()
        self.fast.update(self.zeta.x.array)
        self._assembled = True
        self.timings["assemble_matrix"] += time.perf_counter() - start
