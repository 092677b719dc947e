"""An algebraic Newton residual for a residual whose domain part is affine in u with fixed
coefficients (2.3's (2.137)):

    F(u; w) = a(u, w) + l_n(w) + r(u; w),

a(u, w) the cell integrals' part linear in u (no Function in da/du: K, assembled once, with
the Dirichlet rows of the identity), l_n(w) = F_cell(0; w) the cell integrals at u = 0 (the
memory (M_n, eps(w)) and the body force: they change once per time step, assembled by
:meth:`SplitResidual.begin`), r(u; w) the other integrals (the Gamma_C contact term and the
traction: a boundary assembly per call). A residual evaluation is then K x + l_n + r(x) with
x - g on the Dirichlet rows, as :func:`callbacks.form_callbacks` assembles it, instead of an
assembly over every cell.

The Jacobian is K + dr/du, so the assembled values of dr/du (a boundary assembly) are an exact
key of the Jacobian (:meth:`SplitResidual.jacobian_key`, for NonlinearSolver's
``jacobian_key``): while they are unchanged (the same contact set) the Jacobian is not
re-assembled, and it is bit for bit the one it would be.

Homogeneous Dirichlet conditions only (g = 0, the clamped side); the split is checked once
against the assembled residual at a random u (relative 1e-12).
"""
from __future__ import annotations

import numpy as np
import ufl
from petsc4py import PETSc

from damage_dolfinx import compat
from damage_dolfinx.numerics.callbacks import constant_cell_jacobian

#: largest relative difference to the assembled residual accepted by the set-up check
CHECK_RTOL = 1e-12


def affine_cell_split(F, u):
    """(a, l, r, dr) with F = a(u) + l + r(u) as in the module docstring: a = J_cell (bilinear,
    no Function), l = the cell integrals at u = 0, r = the other integrals, dr = dr/du; None
    when the cell part of dF/du depends on a Function or nothing else varies."""
    split = constant_cell_jacobian(F, u)
    if split is None:
        return None
    J_cell, J_rest = split
    cell = [i for i in F.integrals() if i.integral_type() == "cell"]
    rest = [i for i in F.integrals() if i.integral_type() != "cell"]
    zero = ufl.replace(ufl.Form(cell), {u: ufl.zero(*u.ufl_shape)}) if cell else None
    return J_cell, zero, ufl.Form(rest), J_rest


class SplitResidual:
    """The residual callback (x, b) of NonlinearSolver for F = a(u) + l_n + r(u); call
    :meth:`begin` at the start of each solve (after l_n's coefficients, e.g. M_n and the
    load's time, are set)."""

    def __init__(self, F, u, bcs, split=None):
        J_cell, F_zero, F_rest, J_rest = split or affine_cell_split(F, u)
        self.u, self.bcs = u, list(bcs)
        self.u_vec = compat.petsc_vec(u)
        a = compat.form(J_cell)
        self.K = compat.create_matrix(a)
        compat.assemble_matrix(self.K, a, self.bcs)  # Dirichlet rows: identity
        self.K.assemble()
        self.zero_form = compat.form(F_zero) if F_zero is not None else None
        self.rest_form = compat.form(F_rest)
        self.l = compat.create_vector(self.rest_form)
        self.l.set(0.0)
        self.key_form = compat.form(J_rest)
        self.dr = compat.create_matrix(self.key_form)
        self._check_homogeneous()

    def begin(self):
        """Assemble l_n, the cell integrals at u = 0, for this solve."""
        if self.zero_form is None:
            return
        with self.l.localForm() as ll:
            ll.set(0.0)
        compat.assemble_vector(self.l, self.zero_form)
        self.l.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)

    def __call__(self, x, b):
        """b = K x + l_n + r(x), x - g (= x) on the Dirichlet rows; x is copied into u."""
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        x.copy(self.u_vec)
        self.u.x.scatter_forward()
        with b.localForm() as bl:
            bl.set(0.0)
        compat.assemble_vector(b, self.rest_form)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        self.K.multAdd(x, b, b)
        b.axpy(1.0, self.l)
        compat.set_bc(b, self.bcs, x, -1.0)

    def jacobian_key(self, x) -> np.ndarray:
        """The assembled values of dr/du at u (= x, set by the residual just evaluated at x):
        K + dr/du is the Jacobian, so equal keys mean an equal Jacobian."""
        self.dr.zeroEntries()
        compat.assemble_matrix(self.dr, self.key_form, [])
        self.dr.assemble()
        return self.dr.getValuesCSR()[2].copy()

    def _check_homogeneous(self):
        probe = self.K.createVecLeft()
        probe.set(0.0)
        compat.set_bc(probe, self.bcs)  # the Dirichlet rows <- g
        if probe.norm() != 0.0:
            raise ValueError("SplitResidual: Dirichlet values must be zero")

    def check(self, form_residual) -> float:
        """The relative difference to ``form_residual`` (form_callbacks' assembly) at a random u
        vanishing on the Dirichlet dofs (u restored); raises beyond CHECK_RTOL."""
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
