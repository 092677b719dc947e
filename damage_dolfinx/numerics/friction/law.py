"""The nodal regularised Tresca law (2.99)-(2.101) in NumPy, on the tangential velocities s of the
contact nodes: scalars (shape (nodes,)) in 2-D, tangent-plane vectors (nodes, 2) in 3-D.

    Phi_eps(s) = g s / max(|s|, eps)    (2-D: g max(-1, min(1, s/eps)), the same function)
    F_eps(s)   = g |s|^2 / (2 eps) for |s| <= eps,  g |s| - g eps/2 otherwise

The 2-D branches are the expressions the package used before the 3-D extension, unchanged (2-D results
identical bit for bit); the 3-D branches are the same law with |.| the Euclidean norm, the stick
test |s|^2 <= eps^2 as in the UFL form (contact.Phi_reg_vector)."""
from __future__ import annotations

import numpy as np


def norm(s):
    """|s| per node."""
    return np.abs(s) if s.ndim == 1 else np.sqrt(np.einsum("it,it->i", s, s))


def stick(s, eps):
    """Nodes with |s| <= eps (the regularised stick set)."""
    if s.ndim == 1:
        return np.abs(s) <= eps
    return np.einsum("it,it->i", s, s) <= eps * eps


def project(x):
    """Projection onto the unit ball per node: clip to [-1, 1] (2-D), x / max(1, |x|) (3-D)."""
    if x.ndim == 1:
        return np.clip(x, -1.0, 1.0)
    return x / np.maximum(1.0, norm(x))[:, None]


def phi(s, g, eps):
    """Phi_eps(s) per node (g per node)."""
    if s.ndim == 1:
        return g * np.clip(s / eps, -1.0, 1.0)
    return (g / np.sqrt(np.maximum(np.einsum("it,it->i", s, s), eps * eps)))[:, None] * s


def potential(s, g, eps):
    """F_eps(s) per node (2.101)."""
    a = norm(s)
    if s.ndim == 1:
        return g * np.where(a <= eps, s * s / (2.0 * eps), a - eps / 2.0)
    return g * np.where(stick(s, eps), a * a / (2.0 * eps), a - eps / 2.0)


def jacobian_blocks(s, gm, eps, shift):
    """d(m Phi_eps)/ds per node plus the shift: 3-D only, (nodes, 2, 2): m g/eps I on the stick
    nodes, m g/|s| (I - s s^T/|s|^2) on the sliding ones (as UFL differentiates
    contact.Phi_reg_vector), plus shift m g I."""
    eye = np.eye(s.shape[1])
    a = np.maximum(norm(s), eps)
    n = s / a[:, None]
    slide = eye[None] - np.einsum("it,iu->itu", n, n)
    K = np.where(stick(s, eps)[:, None, None], eye[None] / eps, slide / a[:, None, None])
    return gm[:, None, None] * (K + shift * eye[None])
