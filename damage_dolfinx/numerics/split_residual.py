"""A Newton residual without a cell assembly per evaluation, for a residual whose cell part is
affine in u with fixed coefficients (2.3's (2.137)):

    F(u; w) = F_cell(u; w) + r(u; w),   F_cell(x) = F_cell(x_0) + K (x - x_0),

K = dF_cell/du (no Function in it: assembled once, and again when a Constant in it
changed; Dirichlet rows of the identity), r the
other integrals (the Gamma_C contact term and the traction: a boundary assembly). At the start
of a solve (:meth:`SplitResidual.begin`) the residual is assembled once at the starting point
x_0 as :func:`callbacks.form_callbacks` assembles it, F(x_0), with r(x_0); every evaluation is
then

    F(x) = (r(x) - r(x_0)) + F(x_0) + K (x - x_0),   x - g (= x) on the Dirichlet rows,

a boundary assembly and a product with K instead of an assembly over every cell. The first
evaluation, at x_0, is F(x_0) bit for bit, so Newton's first step is the assembled one; the
later ones differ from the assembly by round-off relative to the increment x - x_0, not to u
(an algebraic K x + F_cell(0) would cancel the elastic stress against the memory term and
lose digits: the 2.3 memory modes then agreed to 8e-12 instead of 8e-13).

The Jacobian is K + dr/du, so the assembled values of dr/du (a boundary assembly) are an exact
key of the Jacobian (:meth:`SplitResidual.jacobian_key`, for NonlinearSolver's
``jacobian_key``: a version raised at each change of the values): while they are unchanged (the same contact set) the Jacobian is not
re-assembled, and it is bit for bit the one it would be.

Homogeneous Dirichlet conditions only (g = 0, the clamped side, which the iterates keep); the
split is checked against the assembled residual at a random u when attached (relative 1e-12).
"""
from __future__ import annotations

import numpy as np
from petsc4py import PETSc

from damage_dolfinx import compat
from damage_dolfinx.numerics.callbacks import constant_cell_jacobian
from damage_dolfinx.numerics.held_data import AssembledFrom

#: largest relative difference to the assembled residual accepted by the set-up check
CHECK_RTOL = 1e-12


def affine_cell_split(F, u):
    """(K, r, dr/du) forms with F = F_cell + r as in the module docstring: K = dF_cell/du (no
    Function), r = the non-cell integrals of F; None when K depends on a Function or F has
    no other integral."""
    split = constant_cell_jacobian(F, u)
    if split is None:
        return None
    import ufl
    rest = [i for i in F.integrals() if i.integral_type() != "cell"]
    return split[0], ufl.Form(rest), split[1]


class SplitResidual:
    """The residual callback (x, b) of NonlinearSolver for F = F_cell + r (module docstring).
    :meth:`attach` it to the solver's assembled residual once, then call :meth:`begin` at the
    start of each solve, with u at the starting point."""

    def __init__(self, u, bcs, split):
        J_cell, F_rest, J_rest = split
        self.u, self.bcs = u, list(bcs)
        self.u_vec = compat.petsc_vec(u)
        self._K_form = compat.form(J_cell)
        self.K = compat.create_matrix(self._K_form)
        self._assemble_K()
        self._K_data = AssembledFrom(J_cell, self.K.getComm().tompi4py())  # its Constants
        self.rest_form = compat.form(F_rest)
        self.F0 = compat.create_vector(self.rest_form)
        self.r0, self.x0, self.dx = self.F0.duplicate(), self.F0.duplicate(), self.F0.duplicate()
        self.key_form = compat.form(J_rest)
        self.dr = compat.create_matrix(self.key_form)
        self._dr_last, self._version = None, 0
        self.form_residual = None
        probe = self.K.createVecLeft()
        probe.set(0.0)
        compat.set_bc(probe, self.bcs)  # the Dirichlet rows <- g
        if probe.norm() != 0.0:
            raise ValueError("SplitResidual: Dirichlet values must be zero")

    def _assemble_K(self):
        self.K.zeroEntries()
        compat.assemble_matrix(self.K, self._K_form, self.bcs)  # Dirichlet rows: identity
        self.K.assemble()

    def begin(self):
        """F(x_0) and r(x_0) at the starting point x_0 = u of this solve (K assembled again
        first if a Constant in it has changed)."""
        if self._K_data.changed():
            self._assemble_K()
        self.u_vec.copy(self.x0)
        self.form_residual(self.x0, self.F0)
        self._assemble_rest(self.r0)

    def _assemble_rest(self, b):
        with b.localForm() as bl:
            bl.set(0.0)
        compat.assemble_vector(b, self.rest_form)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)

    def __call__(self, x, b):
        """b = (r(x) - r(x_0)) + F(x_0) + K (x - x_0), x on the Dirichlet rows; x is copied
        into u."""
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        x.copy(self.u_vec)
        self.u.x.scatter_forward()
        self._assemble_rest(b)
        b.axpy(-1.0, self.r0)
        b.axpy(1.0, self.F0)
        self.dx.waxpy(-1.0, self.x0, x)
        self.K.multAdd(self.dx, b, b)
        compat.set_bc(b, self.bcs, x, -1.0)

    def jacobian_key(self, x) -> np.ndarray:
        """A version number of the assembled values of dr/du at u (= x, set by the residual
        just evaluated at x), raised whenever they differ bit for bit from those of the
        previous call (PETSc's MatEqual: O(nonzeros), collective); K + dr/du is the Jacobian,
        so an unchanged version means an unchanged Jacobian."""
        self.dr.zeroEntries()
        compat.assemble_matrix(self.dr, self.key_form, [])
        self.dr.assemble()
        if self._dr_last is None:
            self._dr_last = self.dr.duplicate(copy=True)
        elif not self.dr.equal(self._dr_last):
            self.dr.copy(self._dr_last, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
            self._version += 1
        return np.array([self._version])

    def attach(self, form_residual) -> float:
        """Use ``form_residual`` (form_callbacks' assembly) for F(x_0); returns the relative
        difference of the two at a random x vanishing on the Dirichlet dofs, from x_0 = the
        current u (u restored), and raises beyond CHECK_RTOL."""
        self.form_residual = form_residual
        saved = self.u.x.array.copy()
        x = self.u_vec.duplicate()
        x.setRandom(PETSc.Random().create(x.getComm()))
        compat.set_bc(x, self.bcs)
        b_form, b_split = x.duplicate(), x.duplicate()
        self.begin()
        form_residual(x, b_form)
        self(x, b_split)
        b_split.axpy(-1.0, b_form)
        change = b_split.norm() / max(b_form.norm(), 1e-300)
        self.u.x.array[:] = saved
        self.u.x.scatter_forward()
        if not change <= CHECK_RTOL:
            raise RuntimeError(f"split residual differs from the assembled one ({change:.2e})")
        return change
