"""Matrices whose entries are linear in the nodal damage zeta, updated by a precomputed sparse map
instead of a re-assembly: ZetaLinearMatrix, and VelocitySolver, the LinearSolver of the
velocity step (3.159) of Section 3.3 built on it. Serial only (see ZetaLinearMatrix)."""
from __future__ import annotations

import time

import numpy as np
from dolfinx import fem
from petsc4py import PETSc

from damage_dolfinx import compat
from damage_dolfinx.numerics.solvers import ConvergenceError, LinearSolver, _reason_name


class ZetaLinearMatrix:
    """The matrix of (3.159), A(zeta) = A_0 + W(zeta) (A_0 = rho/k M with the Dirichlet rows,
    W(zeta) = a_visc(zeta) linear in zeta), as CSR values data_0 + P C zeta: two sparse products
    per step instead of a re-assembly. On P1 the strains are constant on a cell, so
    W(zeta) = sum_cells zbar_c K_c with zbar_c = C zeta the cell mean of zeta (exact: the
    quadrature of a_visc integrates the linear zeta exactly) and K_c the cell's matrix; P holds
    the K_c (about 36 values a cell, half the entries of the map through the nodal zeta). P is
    built once from a few assemblies: the cells get a colouring in which cells of one colour
    share no vertex, so each entry of a_visc(indicator of a colour) comes from a single cell.
    The construction checks W(zeta) against an assembly for a random zeta. Serial only (in
    parallel, rows owned here may get contributions from cells this rank does not hold)."""

    def __init__(self, A, V, a_mass, a_visc, zeta, bcs):
        import scipy.sparse as sp
        Z, msh = zeta.function_space, zeta.function_space.mesh
        bs = V.dofmap.index_map_bs
        compat.assemble_matrix(A, compat.form(a_mass), bcs)             # rho/k M, bc rows
        A.assemble()
        self.indptr, self.indices, self.data0 = (a.copy() for a in A.getValuesCSR())
        n_rows = self.indptr.size - 1
        rows = np.repeat(np.arange(n_rows), np.diff(self.indptr))
        # int64: the vertex-pair keys below reach nv^2 (4.4e9 at n = 256, past int32)
        cz, cv = (compat.cell_dofs(S).astype(np.int64) for S in (Z, V))  # (cells, 3) vertices
        Q = compat.scalar_dg0(msh)
        cq = compat.cell_dofs(Q)[:, 0]                                  # the cell's DG0 dof
        nc, nz, nq = cz.shape[0], zeta.x.array.size, Q.dofmap.index_map.size_local
        # cell means: zbar = C zeta (the centroid value of P1, as the quadrature takes it)
        self.C = sp.csr_matrix((np.full(cz.size, 1.0 / cz.shape[1]),
                                (np.repeat(cq, cz.shape[1]), cz.ravel())), shape=(nq, nz))
        # colouring: cells sharing a vertex get different colours (greedy)
        incidence = sp.csr_matrix((np.ones(cv.size), (np.repeat(np.arange(nc), cv.shape[1]),
                                                      cv.ravel())))
        adj = (incidence @ incidence.T).tocsr()
        colour = np.full(nc, -1)
        for c in range(nc):
            used, col = set(colour[adj.indices[adj.indptr[c]:adj.indptr[c + 1]]].tolist()), 0
            while col in used:
                col += 1
            colour[c] = col
        ncol = colour.max() + 1
        # entry e = (row, column) by vertex pair: key = vertex(row) * nv + vertex(column)
        nv = int(cv.max()) + 1
        entry_key = (rows // bs) * nv + self.indices // bs
        bc_dofs = np.zeros(n_rows, bool)
        for bc in bcs:
            bc_dofs[compat.bc_dofs(bc)] = True
        keep = ~(bc_dofs[rows] | bc_dofs[self.indices])
        ind = fem.Function(Q)
        a_ind = compat.form(a_visc(ind))
        W = compat.create_matrix(a_ind)
        P_rows, P_cols, P_vals = [], [], []
        for col in range(ncol):
            mine = np.flatnonzero(colour == col)
            ind.x.array[:] = 0.0
            ind.x.array[cq[mine]] = 1.0
            W.zeroEntries()
            compat.assemble_matrix(W, a_ind, [])
            W.assemble()
            ip, ix, val = W.getValuesCSR()
            # the single cell of this colour holding both vertices of each entry
            pair_key = (cv[mine][:, :, None] * nv + cv[mine][:, None, :]).reshape(len(mine), -1)
            order = np.argsort(pair_key, axis=None)
            sorted_keys = pair_key.ravel()[order]
            pos = np.minimum(np.searchsorted(sorted_keys, entry_key), sorted_keys.size - 1)
            found = sorted_keys[pos] == entry_key
            cell = mine[order[pos] // pair_key.shape[1]]
            if not (np.array_equal(ip, self.indptr) and np.array_equal(ix, self.indices)) or \
                    np.any((val != 0) & ~found):
                raise RuntimeError("velocity matrix map: sparsity or colouring mismatch")
            sel = keep & found & (val != 0)
            P_rows.append(np.flatnonzero(sel)), P_cols.append(cq[cell[sel]])
            P_vals.append(val[sel])
        W.destroy()
        self.P = sp.csr_matrix((np.concatenate(P_vals), (np.concatenate(P_rows),
                                                         np.concatenate(P_cols))),
                               shape=(self.data0.size, nq))
        self.colours = int(ncol)
        # per step: zbar = C zeta, then W = P zbar as P^T's transpose product (a loop over the
        # cells, 36 values each: faster than the CSR product by rows of ~2 values), into
        # one of two buffers: the last update's W(zeta_n) and the one before, W(zeta_{n-1}),
        # which the right-hand side of the next step needs (product())
        self._C = _petsc_csr(self.C, A.getComm())
        self._Pt = _petsc_csr(self.P.T, A.getComm())
        self._zbar = self._C.createVecLeft()
        # each buffer is also the value array of a PETSc matrix W_mat (the pattern of A), so
        # the right-hand side multiplies with W(zeta_{n-1}) without copying it; the third
        # buffer takes a zeta that is neither of the last two (the first step, a restart)
        self._slots = []
        for _ in range(3):
            z_i, W_i = np.zeros(nz), np.zeros(self.data0.size)
            self._slots.append({"zeta": None, "z": z_i, "W": W_i,
                                "z_vec": PETSc.Vec().createWithArray(z_i, comm=A.getComm()),
                                "W_vec": PETSc.Vec().createWithArray(W_i, comm=A.getComm()),
                                "W_mat": PETSc.Mat().createAIJWithArrays(
                                    A.getSize(), (self.indptr, self.indices, W_i),
                                    comm=A.getComm())})
        self._current = 0
        self._check(A, a_visc, zeta, bcs, keep)
        # the PETSc matrix shares its CSR value array: the update writes it in place
        self.data = self.data0.copy()
        self.mat = PETSc.Mat().createAIJWithArrays(A.getSize(), (self.indptr, self.indices,
                                                                 self.data), comm=A.getComm())

    def _check(self, A, a_visc, zeta, bcs, keep):
        """W(zeta) of the map against an assembly of a_visc(zeta) for a random zeta (outside
        the Dirichlet rows and columns, which hold A_0 only)."""
        z = fem.Function(zeta.function_space)
        z.x.array[:] = np.random.default_rng(0).uniform(0.01, 1.0, z.x.array.size)
        a = compat.form(a_visc(z))
        Wz = compat.create_matrix(a)
        compat.assemble_matrix(Wz, a, [])
        Wz.assemble()
        ip, ix, val = Wz.getValuesCSR()
        Wz.destroy()
        mapped = self.viscous(z.x.array)
        if not (np.array_equal(ip, self.indptr) and np.array_equal(ix, self.indices)) or \
                np.abs(mapped - np.where(keep, val, 0.0)).max() > 1e-12 * np.abs(val).max():
            raise RuntimeError("velocity matrix map: W(zeta) differs from the assembly "
                               "(not a P1 displacement space?)")

    def viscous(self, zeta_values, slot=None):
        """The values of W(zeta) (CSR, the pattern of A): P (C zeta); into ``slot``'s buffer
        (returned) or a new array."""
        if slot is None:
            return self.P @ (self.C @ zeta_values)
        slot["z"][:] = zeta_values
        self._C.mult(slot["z_vec"], self._zbar)
        self._Pt.multTranspose(self._zbar, slot["W_vec"])
        slot["W_mat"].assemble()  # new values: new object state
        slot["zeta"] = slot["z"]
        return slot["W"]

    def product(self, zeta_values) -> PETSc.Mat:
        """W(zeta) as a PETSc matrix, reused from the last two updates where zeta is theirs
        (the right-hand side of step n needs W(zeta_{n-1}), which the update of step n-1
        computed), else computed into the third buffer. Valid until the next update but one."""
        for i in (1 - self._current, self._current, 2):
            slot = self._slots[i]
            if slot["zeta"] is not None and np.array_equal(zeta_values, slot["zeta"]):
                return slot["W_mat"]
        self.viscous(zeta_values, self._slots[2])
        return self._slots[2]["W_mat"]

    def forget(self):
        """The next update() recomputes W (benchmarks time it)."""
        for slot in self._slots:
            slot["zeta"] = None

    def update(self, zeta_values) -> bool:
        """A(zeta) into ``self.mat``; False (unchanged) when zeta is the one of the last update."""
        last = self._slots[self._current]["zeta"]
        if last is not None and np.array_equal(zeta_values, last):
            return False
        self._current = 1 - self._current
        W = self.viscous(zeta_values, self._slots[self._current])
        np.add(self.data0, W, out=self.data)
        self.mat.assemble()  # new object state: the preconditioner is rebuilt
        return True


def _petsc_csr(S, comm):
    """A SciPy sparse matrix as a sequential PETSc AIJ matrix (copied, sorted indices)."""
    S = S.tocsr()
    S.sort_indices()
    return PETSc.Mat().createAIJWithArrays(S.shape, (S.indptr.astype(PETSc.IntType),
                                                     S.indices.astype(PETSc.IntType),
                                                     S.data.copy()), comm=comm)


class VelocitySolver(LinearSolver):
    """LinearSolver of (3.159) whose matrix comes from ZetaLinearMatrix (serial). With ``rhs`` =
    (l_boundary, v_old, u_old, zeta_old, m_visc) (only for Phi_L = identity and homogeneous
    Dirichlet data) the right-hand side is rho/k M v_{n-1} - m_visc a_visc(zeta_{n-1}) u_{n-1}
    (two products with the same maps) plus the assembled boundary terms. ``solve`` is
    LinearSolver.solve with the Python-level calls of a step cut to what a serial run needs:
    no ghost update, the homogeneous Dirichlet rows zeroed on the array."""

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
            self.M = PETSc.Mat().createAIJWithArrays(self.A.getSize(), (
                f.indptr, f.indices, f.data0), comm=self.A.getComm())
            self._tmp = self.b.duplicate()
            self._tmp.set(1.0)  # homogeneous Dirichlet data (clamped): the lifting adds 0
            compat.set_bc(self._tmp, self.bcs)
            bc = np.concatenate([compat.bc_dofs(c) for c in self.bcs] + [np.zeros(0, int)])
            self._lifting = bool(np.any(self._tmp.array[bc] != 0.0))
            # homogeneous data: set_bc writes 0 into the Dirichlet rows (none on the wrench)
            self._bc_rows = np.unique(bc).astype(np.int32)
            self._rhs_vecs = (compat.petsc_vec(rhs[1]), compat.petsc_vec(rhs[2]))
            # b's value array (serial: no ghosts; stable, b owns it). Written through this
            # view, then by PETSc's axpy below, which also renews b's state (cached norms)
            self._b_array = self.b.array

    def assemble_rhs(self):
        if self.rhs is None:
            return super().assemble_rhs()
        start = time.perf_counter()
        _, v_old, u_old, zeta_old, m_visc = self.rhs
        W = self.fast.product(zeta_old.x.array)                        # W(zeta_{n-1})
        b, tmp = self.b, self._tmp
        self._b_array.fill(0.0)
        compat.assemble_vector_array(self._b_array, self.l_boundary)   # contact + load
        v_vec, u_vec = self._rhs_vecs
        self.M.mult(v_vec, tmp)                                         # rho/k M v_{n-1}
        b.axpy(1.0, tmp)
        W.mult(u_vec, tmp)                                    # K_B(zeta_{n-1}) = m_visc W
        b.axpy(-m_visc, tmp)
        if self._lifting:  # not reached by the catalogue (clamped or no Gamma_D)
            compat.apply_lifting(b, self.a, self.bcs)
            compat.set_bc(b, self.bcs)
        elif self._bc_rows.size:
            b.setValues(self._bc_rows, np.zeros(self._bc_rows.size))
            b.assemble()
        self.timings["assemble_rhs"] += time.perf_counter() - start

    def assemble_matrix(self):
        start = time.perf_counter()
        self.fast.update(self.zeta.x.array)
        self._assembled = True
        self.timings["assemble_matrix"] += time.perf_counter() - start

    def solve(self, u):
        """Solve into the Function ``u`` (its values are the CG start); returns the KSP
        iteration count. A failed solve raises ConvergenceError as LinearSolver.solve does."""
        self.assemble_matrix()
        self.assemble_rhs()
        x = self._x_vec(u)
        start = time.perf_counter()
        self.ksp.solve(self.b, x)
        self.timings["solve"] += time.perf_counter() - start
        reason = self.ksp.getConvergedReason()
        if reason < 0:
            r = self.b.duplicate()
            self.A.mult(x, r)
            r.aypx(-1.0, self.b)
            raise ConvergenceError(
                f"{self.prefix}ksp did not converge "
                f"({_reason_name(PETSc.KSP.ConvergedReason, reason)}) "
                f"{self.context.where()}, residual {r.norm():.3e}")
        its = self.ksp.getIterationNumber()
        self.iterations += its
        self.solves += 1
        self.factorizations += 1
        return its

    def _x_vec(self, u):
        if getattr(self, "_x", (None, None))[0] is not u:
            self._x = (u, compat.petsc_vec(u))
        return self._x[1]
