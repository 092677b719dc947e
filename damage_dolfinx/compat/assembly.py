"""Forms, PETSc vectors and matrices, assembly, boundary conditions.

Version-specific calls only (damage_dolfinx.compat); imported from there."""
from __future__ import annotations

import inspect

import numpy as np
import dolfinx.fem.petsc  # noqa: F401  (0.7+ no longer imports it implicitly; compat/__init__ first)
from dolfinx import fem
from petsc4py import PETSc

from damage_dolfinx.core.logs import root_kept


def petsc_vec(u: fem.Function) -> PETSc.Vec:
    """The PETSc vector that wraps a Function's dof array (ghosted)."""
    return u.x.petsc_vec if hasattr(u.x, "petsc_vec") else u.vector


def create_vector(L_form) -> PETSc.Vec:
    try:
        return fem.petsc.create_vector(L_form)
    except TypeError:  # 0.10: takes function spaces
        return fem.petsc.create_vector(fem.extract_function_spaces(L_form))


def create_matrix(a_form, mat_type=None) -> PETSc.Mat:
    """The matrix of a bilinear form; ``mat_type`` e.g. "baij" (the second positional argument
    is mat_type up to 0.9 and kind from 0.10 on: the same strings)."""
    if mat_type is None:
        return fem.petsc.create_matrix(a_form)
    return fem.petsc.create_matrix(a_form, mat_type)


def assemble_vector(b, L_form):
    fem.petsc.assemble_vector(b, L_form)


def assemble_vector_array(b: np.ndarray, L_form):
    """Add the assembled L_form into the array ``b`` (local entries, ghosts included, no ghost
    update): the ndarray path of fem.assemble_vector in 0.5-0.11, without the PETSc local
    form of assemble_vector (a few microseconds a call on small meshes)."""
    fem.assemble_vector(b, L_form)


def assemble_matrix(A, a_form, bcs):
    fem.petsc.assemble_matrix(A, a_form, bcs=bcs)


#: keyword of the lifting / Dirichlet scale factor: 'scale' up to 0.8, 'alpha' from 0.9 on
#: (probed once here, not by catching TypeError on every call of these per-step functions)
_SCALE_KEY = "alpha" if "alpha" in inspect.signature(fem.petsc.set_bc).parameters else "scale"


def apply_lifting(b, a_form, bcs, x0=None, scale=1.0):
    """b -= scale * A (g - x0) on the columns of Dirichlet dofs ('scale' <= 0.8, 'alpha' >= 0.9)."""
    fem.petsc.apply_lifting(b, [a_form], [bcs], [] if x0 is None else [x0],
                            **{_SCALE_KEY: scale})


def dirichlet_values_zero(bcs) -> bool:
    """True when every condition's value is known to be zero (a Constant, an array or a
    Function with only zeros): the lifting b -= A (g - x0) with x0 = 0 then changes nothing.
    The value is ``bc.g`` (0.5+: the given value; 0.9+: the wrapped Constant or Function),
    ``bc.value`` where there is no ``g``; anything else counts as non-zero."""
    for bc in bcs:
        g = getattr(bc, "g", None)
        if g is None:
            g = getattr(bc, "value", None)
        if isinstance(g, np.ndarray):
            values = g
        elif hasattr(g, "x") and hasattr(g.x, "array"):  # a Function
            values = g.x.array
        elif isinstance(getattr(g, "value", None), (np.ndarray, float, int)):  # a Constant
            values = np.asarray(g.value)
        else:
            return False
        if values.dtype.kind not in "fciu" or np.any(values != 0):
            return False
    return True


def set_bc(b, bcs, x0=None, scale=1.0):
    fem.petsc.set_bc(b, bcs, x0, **{_SCALE_KEY: scale})


_FORM_OPTIONS_KEY = "jit_options" if "jit_options" in fem.form.__code__.co_varnames else "jit_params"
_FORM_TYPES = tuple(t for t in (getattr(fem, "FormMetaClass", None), getattr(fem, "Form", None))
                    if isinstance(t, type))


def form(ufl_form, jit_options=None):
    """Compiled form; JIT options are 'jit_params' up to 0.5, 'jit_options' from 0.6 on (the
    user's root logger kept: core/logs.py)."""
    with root_kept(quiet=True):
        if not jit_options:
            return fem.form(ufl_form)
        return fem.form(ufl_form, **{_FORM_OPTIONS_KEY: jit_options})


def assemble_scalar(ufl_or_form, comm) -> float:
    """Globally summed integral of a scalar form (compiled or UFL)."""
    f = ufl_or_form if isinstance(ufl_or_form, _FORM_TYPES) else form(ufl_or_form)
    return comm.allreduce(fem.assemble_scalar(f), op=_mpi_sum())


def _mpi_sum():
    from mpi4py import MPI
    return MPI.SUM


def bc_dofs(bc):
    """Local (unrolled, i.e. scalar) dof indices of a DirichletBC, owned and ghost."""
    return bc.dof_indices()[0]
