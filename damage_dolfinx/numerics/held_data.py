"""What an operator assembled once was assembled from: the Functions and Constants of its form,
and their values at that assembly (:class:`AssembledFrom`).

A solver that keeps a matrix from one solve to the next (a constant matrix, a product taken out
of the right-hand side, the damage step's operator) asks :meth:`AssembledFrom.changed` before
each solve and assembles the matrix again when any of those values differs from the last
assembly's: a datum of the state (a Function the model updates) or a Constant set later is then
never held at its value when the solver was built. When nothing in the form changes (the thesis
models: numbers and fixed Constants), the check is a few byte comparisons per solve and nothing
is assembled again.
"""
from __future__ import annotations

import numpy as np
from mpi4py import MPI


def held(form) -> tuple:
    """(Functions, Constants) a UFL form or expression holds (empty for anything else)."""
    import ufl
    from dolfinx import fem
    from ufl.algorithms.analysis import extract_coefficients, extract_type
    if not isinstance(form, (ufl.Form, ufl.core.expr.Expr)):
        return [], []
    functions = [c for c in extract_coefficients(form) if isinstance(c, fem.Function)]
    constants = [c for c in extract_type(form, ufl.Constant) if hasattr(c, "value")]
    return functions, constants


class AssembledFrom:
    """The Functions and Constants of ``form`` with their values when last asked.

    :meth:`changed` is collective when the form holds Functions (a Function may change on one
    rank's part only; every rank must assemble again together)."""

    def __init__(self, form, comm, functions: bool = True):
        self.functions, self.constants = held(form)
        if not functions:
            self.functions = []
        self.comm = comm
        self._constant_values = [np.asarray(c.value).tobytes() for c in self.constants]
        self._function_values = [f.x.array.copy() for f in self.functions]

    @property
    def names(self) -> str:
        return ", ".join(sorted({getattr(f, "name", "?") for f in self.functions}
                                | {f"Constant {np.array(c.value).tolist()!r}"
                                   for c in self.constants}))

    def changed(self) -> bool:
        """True, on every rank, when a Function or Constant of the form differs from its value
        at the previous call (or at construction); the current values are then recorded."""
        changed = False
        for i, c in enumerate(self.constants):
            now = np.asarray(c.value).tobytes()  # (a bytes comparison: under a microsecond)
            if now != self._constant_values[i]:
                self._constant_values[i] = now
                changed = True
        for f, old in zip(self.functions, self._function_values):
            if not np.array_equal(f.x.array, old):
                old[:] = f.x.array
                changed = True
        if self.functions and self.comm.size > 1:
            changed = self.comm.allreduce(changed, op=MPI.LOR)
        return changed
