"""Coarse-to-fine transfer used by the convergence studies: exact on nested meshes."""
import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from damage_dolfinx import compat
from damage_dolfinx.viz import post
from damage_dolfinx.geometries.square_with_hole import square_with_hole


def test_transfer_reproduces_coarse_interpolant():
    comm = MPI.COMM_WORLD
    coarse, fine = square_with_hole(comm, 10), square_with_hole(comm, 40)
    Vc, Vf = compat.scalar_p1(coarse.mesh), compat.scalar_p1(fine.mesh)
    uc, uf = fem.Function(Vc), fem.Function(Vf)
    # a linear field is reproduced exactly at every fine dof (owned and ghost)
    lin = lambda X: 1.5 * X[0] - 0.7 * X[1] + 0.2  # noqa: E731
    uc.interpolate(lin)
    post.NestedTransfer(Vc, Vf, coarse.grid)(uc, uf)
    want = fem.Function(Vf)
    want.interpolate(lin)
    used = compat.dofs_in_cells(Vf)
    assert np.max(np.abs(uf.x.array[used] - want.x.array[used])) < 1e-12


def test_transfer_is_linear_on_coarse_cells():
    """A nonlinear coarse P1 field and its transfer are the same piecewise-linear function:
    integrals and L2 norms computed on the two meshes agree to round-off."""
    comm = MPI.COMM_WORLD
    coarse, fine = square_with_hole(comm, 5), square_with_hole(comm, 20)
    Vc, Vf = compat.vector_p1(coarse.mesh), compat.vector_p1(fine.mesh)
    uc, uf = fem.Function(Vc), fem.Function(Vf)
    uc.interpolate(lambda X: np.vstack([np.sin(X[0] * X[1]), X[0] ** 2]))
    post.NestedTransfer(Vc, Vf, coarse.grid)(uc, uf)
    for comp in range(2):
        ic = compat.assemble_scalar(uc[comp] * ufl.dx, comm)
        i_f = compat.assemble_scalar(uf[comp] * ufl.dx, comm)
        assert abs(ic - i_f) < 1e-12 * max(1, abs(ic))
        # and so is the L2 norm (the fine field is the same piecewise-linear function)
        nc = compat.assemble_scalar(uc[comp] ** 2 * ufl.dx, comm)
        nf = compat.assemble_scalar(uf[comp] ** 2 * ufl.dx, comm)
        assert abs(nc - nf) < 1e-12 * max(1, nc)


def test_dg0_transfer_of_a_strain_is_exact():
    """The cell-wise strain of a coarse P1 field, transferred as a DG0 tensor (Section 2.4's
    stress space), equals the strain of the transferred P1 field on every fine cell."""
    comm = MPI.COMM_WORLD
    coarse, fine = square_with_hole(comm, 5), square_with_hole(comm, 20)
    uc = fem.Function(compat.vector_p1(coarse.mesh))
    uf = fem.Function(compat.vector_p1(fine.mesh))
    uc.interpolate(lambda X: np.vstack([np.sin(X[0] * X[1]), X[0] ** 2 - X[1]]))
    post.NestedTransfer(uc.function_space, uf.function_space, coarse.grid)(uc, uf)
    Sc, Sf = compat.tensor_dg0(coarse.mesh), compat.tensor_dg0(fine.mesh)
    sc, sf, want = fem.Function(Sc), fem.Function(Sf), fem.Function(Sf)
    compat.interpolate(sc, compat.expression(ufl.sym(ufl.grad(uc)), Sc))
    compat.interpolate(want, compat.expression(ufl.sym(ufl.grad(uf)), Sf))
    post.nested_transfer(Sc, Sf, coarse.grid)(sc, sf)
    owned = compat.cell_dofs(Sf)[:, 0]
    got, ref = sf.x.array.reshape(-1, 4)[owned], want.x.array.reshape(-1, 4)[owned]
    assert np.abs(got - ref).max() < 1e-12 * max(1.0, np.abs(ref).max())
    assert np.abs(ref).max() > 0.1  # not trivially zero
