"""The cost of a step's history scalars: the products and extrema behind ||u||_L2,
||eps(u)||_L2, ||v||_L2, min/max zeta and max |u| (history.csv, summary.json), taken every step.

* :func:`norm_matrix`: the norm matrices of vector fields in symmetric block (SBAIJ) storage,
  one column index per d x d block of the upper triangle: the product reads about half the
  memory of AIJ, which counts in the loop, right after the solves (the same values to
  rounding).
* :func:`norm_operators`: those matrices and the integration vector of a model, assembled once.
* :func:`extrema`: several minima and maxima of owned arrays in one Allreduce (min a = -max -a).
* :func:`max_node_norm`: max over the nodes of |u(x_i)| from the squared components, without
  the temporary of numpy.linalg.norm.
* :func:`sums_and_maxima`: sums and maxima over ranks in ONE Allreduce (an MPI operation that
  adds the first entries and takes the maximum of the others); serially no MPI call.
* :class:`PiecewiseConstantNorm`: ||f||_L2^2 of a DG0 Function (any value shape) as w . f^2,
  w_j = int phi_j dx assembled once: no form assembly per step (2.4's ||sigma_n||_Q).
* :class:`FieldNorms`: the norm operators of a model together with the owned views of its
  fields, looked up once: a history row then costs the two matrix products, three dot
  products and the extrema of zeta, and no lookup; ``carried_parts`` adds ||v||_L2 without a
  third product where u_n = u_{n-1} + k v_n (M u_n = M u_{n-1} + k M v_n).
"""
from __future__ import annotations

import math

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc


def norm_matrix(a_form, block_size: int) -> PETSc.Mat:
    """The assembled matrix of ``a_form`` (symmetric, no boundary conditions), in symmetric
    block storage (SBAIJ: the upper triangle of d x d blocks) when ``block_size`` > 1.
    Assembled into BAIJ directly (MatConvert from AIJ costs far more than the assembly), then
    converted to SBAIJ (cheap): the product reads about half the matrix. In a run's loop, where
    the solves have just evicted the matrices from the caches, that is what a product costs; in
    isolation, with warm caches, SBAIJ is no faster (the measurements: benchmarks/README.md,
    "Why the defaults")."""
    from damage_dolfinx import compat
    A = compat.create_matrix(a_form, "baij" if block_size > 1 else None)
    compat.assemble_matrix(A, a_form, [])
    A.assemble()
    if block_size == 1:
        return A
    # symmetric by construction; newer PETSc refuses the conversion unless the matrix says so
    A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    return A.convert("sbaij")


def norm_operators(V, Z) -> tuple:
    """(M, K_eps, m, |Omega|, y): the mass and strain-norm matrices of the vector space ``V``
    (u^T M u = ||u||_L2^2, u^T K_eps u = ||eps(u)||_L2^2, block storage), m_i = int phi_i of
    the scalar space ``Z`` (m . zeta = int zeta), the domain's measure and a work vector,
    assembled once per model."""
    import ufl
    from damage_dolfinx import compat
    from damage_dolfinx.forms.constitutive import eps
    du, w = ufl.TrialFunction(V), ufl.TestFunction(V)
    mats = [norm_matrix(compat.form(a), V.dofmap.index_map_bs)
            for a in (ufl.inner(du, w) * ufl.dx, ufl.inner(eps(du), eps(w)) * ufl.dx)]
    m_form = compat.form(ufl.TestFunction(Z) * ufl.dx)
    m = compat.create_vector(m_form)
    with m.localForm() as ml:
        ml.set(0.0)
    compat.assemble_vector(m, m_form)
    m.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    return (*mats, m, m.sum(), mats[0].createVecLeft())


def extrema(comm, minima=(), maxima=()) -> tuple[list, list]:
    """(min over ranks of each array in ``minima``, max of each in ``maxima``) in one Allreduce;
    an empty array gives +inf / -inf."""
    local = np.array([-(a.min() if a.size else np.inf) for a in minima]
                     + [a.max() if a.size else -np.inf for a in maxima], dtype=float)
    if comm.size > 1:
        comm.Allreduce(MPI.IN_PLACE, local, op=MPI.MAX)
    k = len(minima)
    return [float(-x) for x in local[:k]], [float(x) for x in local[k:]]


def max_node_norm(values: np.ndarray, dim: int, comm) -> float:
    """max_i |u(x_i)| of an owned P1 vector array (interleaved components), over all ranks."""
    sq = values[0::dim] ** 2
    for c in range(1, dim):
        sq += values[c::dim] ** 2
    return float(np.sqrt(extrema(comm, maxima=[sq])[1][0])) if comm.size > 1 or sq.size else 0.0


def _sum_then_max(inbuf, outbuf, datatype):
    """MPI operation on float64 arrays [count, sums..., maxima...]: adds the ``count`` sums,
    takes the maximum of the rest (count, the same on every rank, is kept)."""
    a = np.frombuffer(inbuf, dtype=np.float64)
    b = np.frombuffer(outbuf, dtype=np.float64)
    k = int(b[0])
    b[1:1 + k] += a[1:1 + k]
    np.maximum(b[1 + k:], a[1 + k:], out=b[1 + k:])


_SUM_THEN_MAX = []


def sums_and_maxima(comm, sums=(), maxima=()) -> tuple[list, list]:
    """(sum over ranks of each value in ``sums``, max over ranks of each in ``maxima``) in one
    Allreduce (a minimum m is the maximum of -m)."""
    buf = np.array([len(sums), *sums, *maxima], dtype=np.float64)
    if comm.size > 1:
        if not _SUM_THEN_MAX:
            _SUM_THEN_MAX.append(MPI.Op.Create(_sum_then_max, commute=True))
        comm.Allreduce(MPI.IN_PLACE, [buf, MPI.DOUBLE], op=_SUM_THEN_MAX[0])
    k = len(sums)
    return [float(x) for x in buf[1:1 + k]], [float(x) for x in buf[1 + k:]]


class PiecewiseConstantNorm:
    """||f||_L2^2 = int f : f dx of a DG0 Function f (scalar, vector or tensor values): the
    integrand is constant on each cell, so the integral is sum_j w_j f_j^2 over the owned dofs,
    with w_j = int phi_j dx (the cell's area or volume, one per component) assembled once. Exact
    (the same terms as the assembled form, summed in another order). ``local()`` is this rank's
    part (add over ranks)."""

    def __init__(self, f):
        import ufl
        from damage_dolfinx import compat
        Q = f.function_space
        w = ufl.TestFunction(Q)
        ones = ufl.as_tensor(np.ones(w.ufl_shape)) if w.ufl_shape else 1.0
        form = compat.form(ufl.inner(ones, w) * ufl.dx)
        vec = compat.create_vector(form)
        with vec.localForm() as local:
            local.set(0.0)
        compat.assemble_vector(vec, form)
        vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        self.weights = vec.getArray(readonly=True).copy()
        vec.destroy()
        self.f = f

    def local(self) -> float:
        """sum_j w_j f_j^2 over the owned dofs, in one pass (no temporary f^2)."""
        values = self.f.x.array[:self.weights.size]
        return float(np.einsum("i,i,i->", self.weights, values, values))


class FieldNorms:
    """This rank's parts of the base scalars of a model with a P1 vector field u and a P1
    scalar field zeta: u^T M u = ||u||_L2^2, u^T K_eps u = ||eps(u)||_L2^2 and m . zeta = int zeta
    (:func:`norm_operators`), and min/max zeta over the owned dofs. The owned value arrays are
    views of the Functions' arrays (valid for the Functions' lifetime), taken once."""

    def __init__(self, u, zeta):
        from damage_dolfinx import compat
        V, Z = u.function_space, zeta.function_space
        self.M, self.K, m, self.area, self.y = norm_operators(V, Z)
        self.m = m.getArray(readonly=True).copy()
        self.u_vec = compat.petsc_vec(u)
        self.u = u.x.array[:V.dofmap.index_map.size_local * V.dofmap.index_map_bs]
        self.zeta = zeta.x.array[:Z.dofmap.index_map.size_local]
        self.y, self.y_array = self.work_vector()

    def work_vector(self) -> tuple:
        """(a PETSc vector of M's rows, its values as a NumPy array): the vector is made on the
        array, so that products written into it are read without VecGetArray."""
        (local, size), _ = self.M.getSizes()
        array = np.zeros(local)
        vec = PETSc.Vec().createWithArray(array, size=(local, size), bsize=self.M.getBlockSize(),
                                          comm=self.M.getComm())
        return vec, array

    def u_parts(self) -> list:
        """[u^T M u, u^T K_eps u] (this rank's parts)."""
        y, y_owned, u, u_owned = self.y, self.y_array, self.u_vec, self.u
        self.M.mult(u, y)
        mass = float(np.dot(u_owned, y_owned))
        self.K.mult(u, y)
        return [mass, float(np.dot(u_owned, y_owned))]

    def carried_parts(self, v, n: int, k: float) -> list:
        """[u^T M u, u^T K_eps u, v^T M v] (this rank's parts) at step ``n`` of a scheme with
        u_n = u_{n-1} + k v_n (``v`` the Function v_n): two products instead of three, M v_n
        and K u_n, with M u_n = M u_{n-1} + k M v_n from the M u kept by the call at step
        n - 1 (a direct product M u_n at any other step: t = 0, after a step without scalars,
        after :meth:`forget`). Equal to the direct products to round-off (relative 1e-16 per
        step)."""
        if not hasattr(self, "_carried"):
            from damage_dolfinx import compat
            self._carried = (*self.work_vector(), *self.work_vector(), compat.petsc_vec(v),
                             v.x.array[:self.u.size])
        Mu, Mu_owned, Mv, Mv_owned, v_vec, v_owned = self._carried
        self.M.mult(v_vec, Mv)
        at = getattr(self, "_Mu_at", None)
        if at == n - 1:
            Mu.axpy(k, Mv)  # M u_n = M u_{n-1} + k M v_n
        elif at != n:
            self.M.mult(self.u_vec, Mu)
        self._Mu_at = n
        self.K.mult(self.u_vec, self.y)
        u = self.u
        return [float(np.dot(u, Mu_owned)), float(np.dot(u, self.y_array)),
                float(np.dot(v_owned, Mv_owned))]

    def mass_parts(self, v) -> float:
        """v^T M v (this rank's part) of a P1 vector Function ``v`` of u's space."""
        if not hasattr(self, "_mass_v"):
            from damage_dolfinx import compat
            self._mass_v = (compat.petsc_vec(v), v.x.array[:self.u.size])
        vec, owned = self._mass_v
        self.M.mult(vec, self.y)
        return float(np.dot(owned, self.y_array))

    def forget(self):
        """The next :meth:`carried_parts` computes M u directly (the state was loaded)."""
        self._Mu_at = None

    def zeta_parts(self) -> tuple:
        """(m . zeta, min zeta, max zeta) over the owned dofs (+inf / -inf where none)."""
        z = self.zeta
        if not z.size:
            return 0.0, np.inf, -np.inf
        return float(np.dot(self.m, z)), float(z.min()), float(z.max())


class AffineStressNorm:
    """||B eps(u) + M||_L2^2 of a P1 vector field u and a DG1 tensor field M (d x d, all d^2
    components stored) on affine simplices, B tau = a tr(tau) I + b tau, without a form
    assembly. On a cell T (vertices i = 0..d, measure |T|) c_T = B eps(u) is constant and M is
    linear with vertex values m_i; with S_T = sum_i m_i and the P1 mass matrix
    int_T phi_i phi_j = |T| (1 + delta_ij) / ((d+1)(d+2)):

        int_T |c + M|^2 = |T| |c + S/(d+1)|^2 + |T| (q/(d+1) - |S|^2/(d+1)^2) / (d+2),
        q = sum_i |m_i|^2

    (|T| |c + mean|^2 plus the integral of |M - mean|^2). sqrt(|T|) c_T comes from a sparse
    matrix of u's local dofs (built once: the P1 gradients of each cell times B), S_T from
    d + 1 vector sums over M's cell blocks, q from one product: about half the cost of the form's
    assembly (benchmarks/README.md, "Why the defaults"). Equal to the assembled form to round-off
    (tests/test_memory_contact_2_3.py). ``local()`` is this rank's part over its owned cells
    (add over ranks). :meth:`applies` says whether the spaces fit (P1 u, DG1 M with d + 1
    dofs per cell, simplices with a P1 geometry)."""

    @staticmethod
    def applies(u, M) -> bool:
        from damage_dolfinx import compat
        V, Q = u.function_space, M.function_space
        msh = V.mesh
        d = msh.topology.dim
        return (msh.geometry.x.shape[1] >= d and compat.geometry_dofmap(msh).shape[1] == d + 1
                and compat.cell_dofs(V).shape[1] == d + 1 and V.dofmap.index_map_bs == d
                and compat.cell_dofs(Q).shape[1] == d + 1 and Q.dofmap.index_map_bs == d * d
                and compat.element_degree(V) == 1 and compat.element_degree(Q) == 1
                and np.allclose(msh.geometry.x[:, d:], 0.0))

    def __init__(self, u, M, a: float, b: float):
        from damage_dolfinx import compat
        V, Q = u.function_space, M.function_space
        d = V.mesh.topology.dim
        cd = compat.cell_dofs(V)  # (owned cells, d + 1) vertex (block) dofs of u
        nc, dd = cd.shape[0], d * d
        x = V.tabulate_dof_coordinates()[:, :d][cd]       # (cells, d + 1, d)
        edges = x[:, 1:, :] - x[:, :1, :]                 # rows x_k - x_0
        inv = np.linalg.inv(edges) if nc else np.zeros((0, d, d))  # columns: grad lambda_k
        volume = np.abs(np.linalg.det(edges)) / math.factorial(d) if nc else np.zeros(0)
        grads = np.concatenate([-inv.sum(axis=2, keepdims=True), inv], axis=2)  # (c, d, d+1)
        root = np.sqrt(volume)
        rows, cols, vals = [], [], []
        cells = np.arange(nc)
        for i in range(d):
            for j in range(d):      # c_ij = a delta_ij tr eps + b (d_j u_i + d_i u_j) / 2
                for v in range(d + 1):
                    for l in range(d):
                        coef = (a * grads[:, l, v] if i == j else 0.0) \
                            + 0.5 * b * ((grads[:, j, v] if l == i else 0.0)
                                         + (grads[:, i, v] if l == j else 0.0))
                        if np.isscalar(coef):
                            continue
                        rows.append((i * d + j) * nc + cells)
                        cols.append(cd[:, v] * d + l)
                        vals.append(root * coef)
        n_u = u.x.array.size
        self.D = _seq_aij(np.concatenate(rows), np.concatenate(cols), np.concatenate(vals),
                          (dd * nc, n_u))
        self.u_vec = PETSc.Vec().createWithArray(u.x.array, comm=PETSc.COMM_SELF)
        self.c = np.zeros(dd * nc)
        self.c_vec = PETSc.Vec().createWithArray(self.c, comm=PETSc.COMM_SELF)
        gc = compat.cell_dofs(Q).ravel()  # DG1 blocks of the owned cells
        blocks = (gc[:, None] * dd + np.arange(dd)).ravel()
        self._take = None if np.array_equal(blocks, np.arange(blocks.size)) else blocks
        self.M, self.n_values = M, blocks.size
        self._m = np.empty(blocks.size)
        self._buf = np.empty(blocks.size)
        self.S = np.empty((dd, nc))
        self.mean_scale = root / (d + 1)                         # sqrt|T| S / (d+1)
        self.q_weight = np.repeat(volume / ((d + 1) * (d + 2)), (d + 1) * dd)
        self.d, self.nc = d, nc

    def local(self) -> float:
        """int over this rank's owned cells of |B eps(u) + M|^2."""
        d, dd, nc = self.d, self.d * self.d, self.nc
        if not nc:
            return 0.0
        self.D.mult(self.u_vec, self.c_vec)             # sqrt|T| c_T, component-major
        values = self.M.x.array
        m = values[:self.n_values] if self._take is None else \
            np.take(values, self._take, out=self._m)
        blocks = m.reshape(nc, d + 1, dd).transpose(1, 2, 0)  # (vertex, component, cell)
        S = self.S
        np.add(blocks[0], blocks[1], out=S)
        for i in range(2, d + 1):
            np.add(S, blocks[i], out=S)
        S *= self.mean_scale                             # sqrt|T| S / (d + 1)
        S = S.ravel()
        t = np.add(S, self.c, out=self.c)                # sqrt|T| (c + mean m)
        # einsum, not np.dot: the reference BLAS's ddot is slower here
        mean_part = float(np.einsum("i,i->", t, t))
        spread = float(np.multiply(np.multiply(m, m, out=self._buf), self.q_weight,
                                   out=self._buf).sum())
        # int |M - mean|^2 = sum |T| q/((d+1)(d+2)) - |sqrt|T| S/(d+1)|^2/(d+2)
        return mean_part + spread - float(np.einsum("i,i->", S, S)) / (d + 2)


def _seq_aij(rows, cols, vals, shape) -> PETSc.Mat:
    """A serial AIJ matrix (this rank's local rows and columns) from COO entries (summed)."""
    order = np.lexsort((cols, rows))
    rows, cols, vals = rows[order], cols[order], vals[order]
    keep = np.ones(rows.size, bool)
    keep[1:] = (rows[1:] != rows[:-1]) | (cols[1:] != cols[:-1])
    start = np.flatnonzero(keep)
    vals = np.add.reduceat(vals, start) if vals.size else vals
    rows, cols = rows[start], cols[start]
    indptr = np.zeros(shape[0] + 1, dtype=PETSc.IntType)
    np.cumsum(np.bincount(rows, minlength=shape[0]), out=indptr[1:])
    A = PETSc.Mat().createAIJ(size=shape, csr=(indptr, cols.astype(PETSc.IntType), vals),
                              comm=PETSc.COMM_SELF)
    A.assemble()
    return A
