"""UFL residual and Jacobian callbacks for the SNES of solvers.py: the plain assembly
(:func:`form_callbacks`, the pattern of fenicsx-patterns section 2) and the split Jacobian of a
residual whose domain part is linear with fixed coefficients (:func:`constant_cell_jacobian`:
the constant part assembled once, the rest, e.g. a Gamma_C contact term, per Newton step)."""
from __future__ import annotations

import numpy as np
from petsc4py import PETSc

from damage_dolfinx import compat
from damage_dolfinx.numerics.held_data import AssembledFrom


def form_callbacks(F, J, u, bcs, jacobian_split=None):
    """(residual, jacobian, b, A) callbacks for SNESSolver from UFL forms F(u; w), J = dF/du.

    The usual DOLFINx pattern for a SNES: the SNES iterate is copied into
    ``u`` before assembly, Dirichlet rows are set to x - g so that the BC holds at convergence.
    ``jacobian_split`` = (J_constant, J_varying) with J = J_constant + J_varying, J_constant
    independent of u and of time (no Function in it): J_constant is assembled once (with the
    Dirichlet identity rows), each Jacobian is a copy of it plus an assembly of J_varying
    alone (2.3's normal compliance, a Gamma_C integral, instead of the whole domain).
    """
    F_form, J_form = compat.form(F), compat.form(J)
    u_vec = compat.petsc_vec(u)

    def residual(x, b):
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        x.copy(u_vec)
        u.x.scatter_forward()
        with b.localForm() as bl:
            bl.set(0.0)
        compat.assemble_vector(b, F_form)
        compat.apply_lifting(b, J_form, bcs, x, -1.0)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        compat.set_bc(b, bcs, x, -1.0)

    def jacobian(x, A):
        A.zeroEntries()
        compat.assemble_matrix(A, J_form, bcs)
        A.assemble()

    A = compat.create_matrix(J_form)
    if jacobian_split is not None:
        jacobian = _split_jacobian(jacobian, J_form, *jacobian_split, A, bcs, u)
    return residual, jacobian, compat.create_vector(F_form), A


def constant_cell_jacobian(F, u):
    """(J_constant, J_varying) for form_callbacks' ``jacobian_split``: the cell integrals of
    J = dF/du when they contain no Function (F linear in u over the domain with fixed
    coefficients, e.g. 2.3's B eps(u) + M_n), the other integrals (e.g. a Gamma_C contact
    term) varying; None when the cell part depends on a Function or nothing varies."""
    import ufl
    from ufl.algorithms import expand_derivatives
    J = expand_derivatives(ufl.derivative(F, u, ufl.TrialFunction(u.function_space)))
    cell = [i for i in J.integrals() if i.integral_type() == "cell"]
    other = [i for i in J.integrals() if i.integral_type() != "cell"]
    if not cell or not other or any(isinstance(c, ufl.Coefficient) for c in
                                    ufl.algorithms.extract_coefficients(ufl.Form(cell))):
        return None
    return ufl.Form(cell), ufl.Form(other)


def _split_jacobian(full_jacobian, J_form, J_constant, J_varying, A, bcs, u):
    """The Jacobian callback of form_callbacks' ``jacobian_split``: A = K + J_varying(u), K =
    J_constant assembled once into the pattern of J. DOLFINx inserts (not adds) the Dirichlet
    diagonal, so the second assembly leaves K's identity rows as they are; the split is
    checked once against the assembly of J on a random u (relative Frobenius 1e-12)."""
    import ufl
    if any(isinstance(c, ufl.Coefficient) for c in ufl.algorithms.extract_coefficients(
            J_constant)):
        raise ValueError("J_constant of a split Jacobian depends on a Function")
    K = compat.create_matrix(J_form)
    full_jacobian(None, K)  # the pattern of an assembled J, the one A gets below
    K.zeroEntries()
    constant = compat.form(J_constant)
    compat.assemble_matrix(K, constant, bcs)
    K.assemble()
    varying = compat.form(J_varying)
    constant_data = AssembledFrom(J_constant, K.getComm().tompi4py())  # its Constants

    def jacobian(x, A):
        if not A.isAssembled():  # a new matrix (e.g. a lagged preconditioner): its pattern
            full_jacobian(x, A)
            return
        if constant_data.changed():  # a Constant of J_constant changed: K anew
            K.zeroEntries()
            compat.assemble_matrix(K, constant, bcs)
            K.assemble()
        K.copy(A, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        compat.assemble_matrix(A, varying, bcs)
        A.assemble()

    _check_split(jacobian, full_jacobian, A, u)
    return jacobian


def _check_split(jacobian, full_jacobian, A, u):
    """The split Jacobian against the full assembly at a random u (u is restored)."""
    saved = u.x.array.copy()
    u.x.array[:] = np.random.default_rng(0).standard_normal(saved.shape)
    u.x.scatter_forward()
    full_jacobian(None, A)
    full = A.duplicate(copy=True)
    jacobian(None, A)
    u.x.array[:] = saved
    u.x.scatter_forward()
    change = relative_change(A, full)
    full.destroy()
    if not change <= 1e-12:
        raise RuntimeError(f"split Jacobian differs from the assembled one ({change:.2e})")


def relative_change(A, P) -> float:
    """||A - P||_F / ||P||_F for matrices with the same sparsity."""
    D = A.duplicate(copy=True)
    D.axpy(-1.0, P, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
    change = D.norm(PETSc.NormType.FROBENIUS) / max(P.norm(PETSc.NormType.FROBENIUS), 1e-300)
    D.destroy()
    return change
