"""Constitutive pieces of the thesis, as UFL expressions (plane stress, small strain).

Each function is a pure map of UFL expressions; the numbers in brackets are thesis equations,
stated in docs/models.md ("Common notation"). ``B``, ``Phi_L``, ``split_norms_sq`` and
``von_mises`` take the dimension from their tensor argument: 2x2 gives the thesis' plane-stress
expressions unchanged, 3x3 the 3-D ones of ``constitutive3d.py``.
"""
from __future__ import annotations

import math

import ufl

from damage_dolfinx.forms import constitutive3d

#: regulariser under the square root of the principal-strain formula (tension/compression split)
SPLIT_EPS = 1e-30


def eps(u):
    """Linearised strain eps(u) = sym(grad u)."""
    return ufl.sym(ufl.grad(u))


def B_plane_stress(tau, E, nu):
    """Plane-stress elasticity (2.36): (B tau)_ab = E nu/(1-nu^2) tr(tau) d_ab + E/(1+nu) tau_ab."""
    return E * nu / (1.0 - nu**2) * ufl.tr(tau) * ufl.Identity(2) + E / (1.0 + nu) * tau


def B(tau, E, nu):
    """Elasticity of the tensor's dimension: plane stress (2.36) for 2x2, isotropic 3-D for 3x3."""
    if _dim(tau) == 3:
        return constitutive3d.B_isotropic(tau, E, nu)
    return B_plane_stress(tau, E, nu)


def B_coefficients(dim: int, E, nu) -> tuple:
    """(a, b) with B tau = a tr(tau) I + b tau, the B of :func:`B` on dim x dim tensors."""
    if dim == 3:
        lmbda, mu = constitutive3d.lame(E, nu)
        return lmbda, 2.0 * mu
    return E * nu / (1.0 - nu**2), E / (1.0 + nu)


def _dim(tau) -> int:
    return tau.ufl_shape[0]


def clip(x, lo, hi):
    return ufl.max_value(lo, ufl.min_value(hi, x))


def Phi_L(tau, L):
    """Componentwise truncation (2.107): (Phi_L tau)_ij = max(-L, min(L, tau_ij)); L = inf is identity."""
    if L is None or math.isinf(L):
        return tau
    d = _dim(tau)
    return ufl.as_matrix([[clip(tau[i, j], -L, L) for j in range(d)] for i in range(d)])


def eta_star(r, zeta_star):
    """Damage truncation eta_*(r) = min(1, max(zeta_star, r)) (Section 1.3)."""
    return clip(r, zeta_star, 1.0)


def Psi_q(tau, q_star):
    """Strain-energy cap Psi_q(tau) = min(tau:tau, q_star)."""
    return ufl.min_value(ufl.inner(tau, tau), q_star)


def principal_strains(e):
    """Closed-form eigenvalues l_{1,2} = tr/2 +- sqrt(((e11-e22)/2)^2 + e12^2) of a 2x2 symmetric tensor."""
    mean = 0.5 * (e[0, 0] + e[1, 1])
    rad = ufl.sqrt(((e[0, 0] - e[1, 1]) / 2.0) ** 2 + e[0, 1] ** 2 + SPLIT_EPS)
    return mean + rad, mean - rad


def split_norms_sq(e):
    """(|eps^+|^2, |eps^-|^2): squared norms of the tension and compression parts of ``e``."""
    if _dim(e) == 3:
        return constitutive3d.split_norms_sq(e)
    l1, l2 = principal_strains(e)
    pos = ufl.max_value(l1, 0.0) ** 2 + ufl.max_value(l2, 0.0) ** 2
    neg = ufl.min_value(l1, 0.0) ** 2 + ufl.min_value(l2, 0.0) ** 2
    return pos, neg


def von_mises(s):
    """Plane-stress von Mises value sqrt(s11^2 - s11 s22 + s22^2 + 3 s12^2) (docs/models.md,
    "Output conventions"); the 3-D value sqrt(3/2 dev(s):dev(s)) for a 3x3 tensor."""
    if _dim(s) == 3:
        return constitutive3d.von_mises(s)
    return ufl.sqrt(s[0, 0] ** 2 - s[0, 0] * s[1, 1] + s[1, 1] ** 2 + 3.0 * s[0, 1] ** 2 + 1e-300)
