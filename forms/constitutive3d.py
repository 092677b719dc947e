"""The 3-D counterparts of the plane-stress pieces of ``constitutive.py``, as UFL
expressions of 3x3 tensors. ``constitutive.py`` dispatches to them on the tensor's shape, so a
stepper takes the dimension from its mesh; the 2-D expressions are untouched.

The thesis is 2-D, plane stress (docs/models.md, "Common notation"); these are the standard 3-D
objects the model reduces from: isotropic Hooke's law, whose plane-stress reduction is B (2.36),
and the tension/compression split of Section 1.3 (thesis (1.4)) from the eigenvalues of a
symmetric 3x3 strain.
"""
from __future__ import annotations

import math

import ufl

#: regulariser under the square root of the deviatoric size p (zero strain is the initial state
#: of every example: p = 0 there, and B = (e - q I)/p would be 0/0)
SPLIT3_EPS = 1e-30


def lame(E, nu):
    """Lame constants (lambda, mu) of Young's modulus E and Poisson's ratio nu (3-D)."""
    return E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), E / (2.0 * (1.0 + nu))


def B_isotropic(tau, E, nu):
    """3-D isotropic elasticity: B tau = lambda tr(tau) I + 2 mu tau. Its plane-stress reduction
    (sigma_i3 = 0) is the B of (2.36): E nu/(1-nu^2) tr(tau) I + E/(1+nu) tau, as 2 mu = E/(1+nu)."""
    lmbda, mu = lame(E, nu)
    return lmbda * ufl.tr(tau) * ufl.Identity(3) + 2.0 * mu * tau


def principal_strains(e):
    """Eigenvalues (l1 >= l2 >= l3) of a symmetric 3x3 tensor in closed form (trigonometric
    solution of the characteristic cubic, O. K. Smith, CACM 4 (1961) 168).

    q = tr(e)/3, p = sqrt(|e - q I|^2 / 6), r = det((e - q I)/p)/2 in [-1, 1],
    phi = acos(r)/3, l1 = q + 2p cos(phi), l3 = q + 2p cos(phi + 2 pi/3), l2 = 3q - l1 - l3.

    Repeated eigenvalues: for two equal ones r = +-1 (clipped against round-off, so acos is
    always defined); for three equal ones (zero strain) p = 0 and the regulariser SPLIT3_EPS
    makes (e - q I)/p = 0, r = 0, all three l = q up to 2 sqrt(SPLIT3_EPS/6) ~ 1e-15. A round-off
    delta in r = +-1 moves the repeated pair by O(sqrt(delta)) p in opposite directions, which
    changes sums of squares (all the split needs) only at second order, O(delta) p^2.
    """
    q = ufl.tr(e) / 3.0
    d = e - q * ufl.Identity(3)
    p = ufl.sqrt(ufl.inner(d, d) / 6.0 + SPLIT3_EPS)
    r = ufl.max_value(-1.0, ufl.min_value(1.0, ufl.det(d / p) / 2.0))
    phi = ufl.acos(r) / 3.0
    l1 = q + 2.0 * p * ufl.cos(phi)
    l3 = q + 2.0 * p * ufl.cos(phi + 2.0 * math.pi / 3.0)
    return l1, 3.0 * q - l1 - l3, l3


def split_norms_sq(e):
    """(|eps^+|^2, |eps^-|^2) of a symmetric 3x3 strain: sums of the squared positive / negative
    eigenvalues (the tension/compression split of the damage source), evaluated explicitly
    (never differentiated)."""
    ls = principal_strains(e)
    pos = sum(ufl.max_value(l, 0.0) ** 2 for l in ls)
    neg = sum(ufl.min_value(l, 0.0) ** 2 for l in ls)
    return pos, neg


def von_mises(s):
    """3-D von Mises value sqrt(3/2 dev(s):dev(s)); equal to the plane-stress formula of
    docs/models.md ("Output conventions") when s_i3 = 0."""
    d = ufl.dev(s)
    return ufl.sqrt(1.5 * ufl.inner(d, d) + 1e-300)
