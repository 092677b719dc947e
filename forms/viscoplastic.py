"""Section 2.4: elastic-viscoplastic body, scheme (2.184)-(2.187).

    Ghat_n = P_Q[G(sigma_{n-1}, zeta_{n-1})],  G = s (1 - zeta) Phi_L(sigma)   (Section 2.4.3, s = +1)
    w = delta u_n in V:  k (B eps(w), eps(v - w)) + j(v) - j(w)
                         >= L_n(v - w) - (sigma_{n-1}, eps(v - w)) - k (Ghat_n, eps(v - w))   (2.187)
    sigma_n = sigma_{n-1} + k P_Q[B eps(w)] + k Ghat_n                                        (2.184)

Q^h = piecewise-constant tensors; B eps(w) is constant on each cell for P1 w, and
(1 - zeta) Phi_L(sigma) is affine on each cell for P1 zeta and P0 sigma, so both projections are
the cell values at the centroid (interpolation into DG0 = L2 projection; tested).
"""
import ufl

from damage_dolfinx.forms.constitutive import B, Phi_L, eps

from damage_dolfinx.forms.elastic_damage import load


def viscoplastic_rate(sigma, zeta, L_trunc, sign=1.0):
    """G(sigma, eps(u), zeta) = sign (1 - zeta) Phi_L(sigma) (thesis: sign = +1; docs/models.md,
    section 2.4)."""
    return sign * (1.0 - zeta) * Phi_L(sigma, L_trunc)


def stress_update(sigma_old, w, G_hat, k, E, nu):
    """sigma_n = sigma_{n-1} + k B eps(w) + k Ghat_n (2.184), evaluated cell-wise."""
    return sigma_old + k * B(eps(w), E, nu) + k * G_hat


def increment_step_forms(w, v, sigma_old, G_hat, k, E, nu, f_B, f_N, dsN, S_n=None, normal=None,
                         dsC=None):
    """(a, l) of the increment VI (2.187) without j: a(w, v) = k (B eps(w), eps(v)),
    l(v) = L_n(v) - (sigma_{n-1}, eps(v)) - k (Ghat_n, eps(v)) [+ S_n (v.nu)_{Gamma_C} for P2]."""
    a = k * ufl.inner(B(eps(w), E, nu), eps(v)) * ufl.dx
    l = -ufl.inner(sigma_old + k * G_hat, eps(v)) * ufl.dx
    if S_n is not None:  # simplified Coulomb (2.154): prescribed normal stress on Gamma_C
        l += S_n * ufl.dot(v, normal) * dsC
    L = load(v, f_B, f_N, dsN)
    return a, (l if L is None else l + L)
