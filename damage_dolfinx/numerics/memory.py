"""Long-memory term of Section 2.3 by the left rectangle rule (2.136):

    M_n = sum_{j=1..n} k a(t_n - t_{j-1}) g_{j-1},   g_j = zeta_j Phi_L(B eps(u_j)),

for separable kernels G(tau, eps, zeta) = a(tau) g(eps, zeta). Three evaluations, cross-checked
in the tests:

* ``running``   (a = A constant, Examples 1-2):  M_n = M_{n-1} + k A g_{n-1}, O(1) per step;
* ``recursive`` (a = A exp(-r tau), Example 3):   M_n = exp(-r k) (M_{n-1} + k A g_{n-1}), O(1);
* ``sum``       (any a): the plain sum over the stored history, O(n) work and storage per step.

M and g live in a DG1 tensor space (exact: zeta is P1 and Phi_L(B eps(u)) cell-wise constant).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from dolfinx import fem

from damage_dolfinx import compat
from damage_dolfinx.parameters import InputError


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
        step n-1."""
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
