"""Long-memory term of Section 2.3 by the left rectangle rule (2.136):

    M_n = sum_{j=1..n} k a(t_n - t_{j-1}) g_{j-1},   g_j = zeta_j Phi_L(B eps(u_j)),

for separable kernels G(tau, eps, zeta) = a(tau) g(eps, zeta). Three evaluations, cross-checked
in the tests:

* ``running``   (a = A constant, Examples 1-2):  M_n = M_{n-1} + k A g_{n-1}, O(1) per step;
* ``recursive`` (a = A exp(-r tau), Example 3):   M_n = exp(-r k) (M_{n-1} + k A g_{n-1}), O(1);
* ``sum``       (any a): the plain sum over the stored history, O(n) work and storage per step.

M and g live in a DG1 tensor space (exact: zeta is P1 and Phi_L(B eps(u)) cell-wise constant).
:class:`CellwiseIntegrand` writes g = zeta S from S = Phi_L(B eps(u)) evaluated at one
point per cell and the vertex values of zeta: the same values as the interpolation
of zeta S into DG1 (to round-off: tests/test_memory_contact_2_3.py), at a third of its
points.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from dolfinx import fem

from damage_dolfinx import compat
from damage_dolfinx.core.parameters import InputError


@dataclass(frozen=True)
class MemoryKernel:
    """a(tau) = amplitude (constant) or amplitude * exp(-rate tau) (exponential)."""
    kind: str = "constant"
    amplitude: float = 1.0
    rate: float = 1.0

    def __call__(self, tau):
        if self.kind == "constant":
            return self.amplitude * np.ones_like(np.asarray(tau, float))
        return self.amplitude * np.exp(-self.rate * np.asarray(tau, float))


class MemoryTerm:
    """M_n in a DG1 tensor Function ``self.M``; call ``update(g_expr)`` once per step with the
    compiled expression of g_{n-1} (evaluated at the state of step n-1)."""

    def __init__(self, msh, kernel: MemoryKernel, k: float, mode: str = "auto"):
        if mode == "auto":
            mode = "running" if kernel.kind == "constant" else "recursive"
        if (mode, kernel.kind) in (("running", "exponential"), ("recursive", "constant")):
            raise InputError(f"memory mode {mode!r} does not apply to a {kernel.kind} kernel "
                             "(use 'sum' or the matching mode)")
        self.kernel, self.k, self.mode = kernel, float(k), mode
        d = msh.topology.dim  # 2x2 (the thesis) or 3x3 tensors
        self.space = compat.function_space(msh, "DG", 1, (d, d))
        self.M = fem.Function(self.space, name="memory")
        self.g = fem.Function(self.space, name="memory_integrand")
        self.history = []  # g_0, g_1, ... ('sum' mode only)
        self.n = 0

    def update(self, g_expr):
        """M_{n} from M_{n-1} and g_{n-1}: ``g_expr`` is the compiled fem.Expression of g at
        step n-1, or a callable that writes g into the Function it is given
        (:class:`CellwiseIntegrand`)."""
        if callable(g_expr):
            g_expr(self.g)
        else:
            compat.interpolate(self.g, g_expr)
        g, k, a = self.g.x.array, self.k, self.kernel
        self.n += 1
        if self.mode == "running":
            self.M.x.array[:] += k * a.amplitude * g
        elif self.mode == "recursive":
            self.M.x.array[:] = math.exp(-a.rate * k) * (self.M.x.array + k * a.amplitude * g)
        else:
            self.history.append(g.copy())
            tau = k * (self.n - np.arange(self.n))  # t_n - t_{j-1}, j = 1..n
            weights = k * a(tau)
            self.M.x.array[:] = weights @ np.asarray(self.history)


class CellwiseIntegrand:
    """g = zeta S in a DG1 tensor space, S a cell-wise constant tensor expression (e.g.
    Phi_L(B eps(u)) with P1 u on simplices): S is evaluated at one point per cell (the DG0
    interpolation point, by the compiled expression's ``eval``: no interpolation into a
    Function), then each cell's DG1 block at vertex i is zeta(vertex i) S. Call with the DG1
    Function g to fill."""

    def __init__(self, S_expr, zeta: fem.Function, g_space):
        msh = zeta.function_space.mesh
        d = msh.topology.dim
        self.mesh, self.comps = msh, d * d
        self.expr = compat.expression(S_expr, compat.function_space(msh, "DG", 0, (d, d)))
        self.zeta = zeta
        zc = compat.cell_dofs(zeta.function_space)  # (owned cells, d + 1) vertex dofs of zeta
        gc = compat.cell_dofs(g_space)              # (owned cells, d + 1) DG1 tensor blocks
        if gc.shape != zc.shape or g_space.dofmap.index_map_bs != self.comps:
            raise ValueError("CellwiseIntegrand: g must live in the DG1 tensor space")
        self.cells = np.arange(zc.shape[0], dtype=np.int32)
        # the usual numbering (cell c holds the DG1 blocks (d+1)c ...): the product in place
        self._gc = None if np.array_equal(gc.ravel(), np.arange(gc.size)) else gc.ravel()
        self._zc, self._z = zc, np.empty(zc.shape)

    def __call__(self, g: fem.Function):
        c = self.comps
        S = compat.eval_expression(self.expr, self.mesh, self.cells).reshape(-1, c)
        z = np.take(self.zeta.x.array, self._zc, out=self._z)  # (cells, d + 1)
        # g[cell, vertex, :] = z[cell, vertex] S[cell, :] (einsum: faster than broadcasting)
        values = g.x.array.reshape(-1, c)
        if self._gc is None:
            np.einsum("ij,ik->ijk", z, S, out=values[:z.size].reshape(z.shape + (c,)))
        else:
            values[self._gc] = np.einsum("ij,ik->ijk", z, S).reshape(-1, c)
        g.x.scatter_forward()
