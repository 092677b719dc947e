"""Damage laws: the source phi(eps, zeta) that drives the damage equation of every model.

Every model advances the damage by the same step (the PDE or the obstacle problem over
[zeta*, 1], see the models page): find zeta_n with

    (zeta_n - zeta_{n-1}, xi) + k kappa (grad zeta_n, grad xi) = k (phi(eps(u), zeta_{n-1}), xi),

where phi is the *damage law*. A law is any function ``(eps, zeta, params) -> UFL scalar`` of the
strain tensor ``eps`` (a UFL 2x2 or 3x3 tensor), the damage ``zeta`` (a UFL scalar) and the run's
:class:`~damage_dolfinx.ModelParameters` ``params``: wrap it in :class:`DamageLaw` and give it to
:class:`~damage_dolfinx.Problem`. Negative values damage the material (zeta decreases), positive
values heal it.

The thesis laws are two instances, chosen by ``params.variant``:

* ``THESIS_A``, variant A (1.3): phi = lam_D (1 - eta(zeta))/eta(zeta) - lam_u/2 Psi_q(eps) - lam_w;
* ``THESIS_B``, variant B (1.4): phi = lam_D (1 - zeta)/eta(zeta) - lam_u^-/2 Psi_q(eps^-)
  - lam_u^+/2 Psi_q(eps^+) - lam_w, with the tension/compression split eps^+-,

with eta(zeta) = max(zeta, zeta*) and Psi_q(e) = min(|e|^2, q*).

Example, a threshold law that damages only beyond a strain eps0 (``params.extra`` holds the user's
own data, given as ``Problem(params={"lam": 500.0, "eps0": 1e-3})``)::

    import ufl
    from damage_dolfinx import DamageLaw

    def threshold(eps, zeta, p):
        return -p.extra["lam"] * ufl.max_value(ufl.inner(eps, eps) - p.extra["eps0"] ** 2, 0.0)

    law = DamageLaw(threshold, name="threshold")

Irreversibility (``Problem(irreversible=True)``) is not part of the law: it is the upper bound
zeta_n <= zeta_{n-1} of the damage step, whatever the law.
"""
from __future__ import annotations

from typing import Callable


class DamageLaw:
    """A damage source phi(eps, zeta, params) -> UFL scalar, with a name for the run records.

    ``source`` must build a UFL expression from UFL arguments only (no NumPy): it is compiled
    once, then evaluated at every step from the previous step's state."""

    def __init__(self, source: Callable, name: str = "user"):
        if not callable(source):
            from damage_dolfinx.core.parameters import InputError
            raise InputError(f"a damage law needs a callable (eps, zeta, params) -> UFL, got {source!r}")
        self.source, self.name = source, str(name)

    def __call__(self, eps, zeta, params):
        return self.source(eps, zeta, params)

    def __repr__(self):
        return f"DamageLaw({self.name!r})"


def _phi_A(e, z, p):
    from damage_dolfinx.numerics.damage import phi_A
    return phi_A(e, z, p)


def _phi_B(e, z, p):
    from damage_dolfinx.numerics.damage import phi_B
    return phi_B(e, z, p)


#: the thesis law of variant A, (1.3)
THESIS_A = DamageLaw(_phi_A, "thesis-A")
#: the thesis law of variant B, (1.4), with the tension/compression split of the strain
THESIS_B = DamageLaw(_phi_B, "thesis-B")


def thesis_law(variant: str) -> DamageLaw:
    """The thesis law of ``variant`` ('A': (1.3), 'B': (1.4))."""
    return {"A": THESIS_A, "B": THESIS_B}[variant]
