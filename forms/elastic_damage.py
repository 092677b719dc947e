"""Section 2.1: quasistatic elastic body with damage, no contact.

Equilibrium (2.21) with the new damage: (eta_*(zeta_n) B eps(u_n), eps(w)) = L_n(w),
L_n(w) = (f_B(t_n), w) + (f_N(t_n), w)_{Gamma_N}.
"""
import ufl

from damage_dolfinx.forms.constitutive import B, eps, eta_star


def stress(u, zeta, E, nu, zeta_star):
    """sigma = eta_*(zeta) B eps(u) (Section 2.1); B of the mesh's dimension (plane stress in 2-D)."""
    return eta_star(zeta, zeta_star) * B(eps(u), E, nu)


def load(w, f_B, f_N, dsN):
    """L_n(w) = (f_B, w) + (f_N, w)_{Gamma_N}; either load may be None (both None -> None)."""
    terms = []
    if f_B is not None:
        terms.append(ufl.inner(f_B, w) * ufl.dx)
    if f_N is not None:
        terms.append(ufl.inner(f_N, w) * dsN)
    return sum(terms[1:], terms[0]) if terms else None


def equilibrium_forms(u, w, zeta, E, nu, zeta_star, f_B, f_N, dsN):
    """(a, L) of (2.21): u, w are trial/test functions of V^h, zeta the new damage."""
    a = ufl.inner(stress(u, zeta, E, nu, zeta_star), eps(w)) * ufl.dx
    return a, load(w, f_B, f_N, dsN)
