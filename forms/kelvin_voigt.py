"""Kelvin-Voigt stresses and the quasistatic velocity step of Section 2.2 (2.67):

    (A eps(v_n), eps(w)) + j(w) - j(v_n) >= L_n(w - v_n) - (zeta_{n-1} Phi_L(B eps(u_{n-1})), eps(w - v_n)),

A = B / m_visc (viscosity, implicit), damaged truncated elasticity explicit (2.106).
"""
import ufl

from damage_dolfinx.forms.constitutive import B, Phi_L, eps

from damage_dolfinx.forms.elastic_damage import load


def viscous_stress(v, E, nu, m_visc):
    """A eps(v) with A = B / m_visc."""
    return B(eps(v), E, nu) / m_visc


def damaged_elastic_stress(u, zeta, E, nu, L_trunc):
    """zeta Phi_L(B eps(u)) (2.106)."""
    return zeta * Phi_L(B(eps(u), E, nu), L_trunc)


def kelvin_voigt_stress(v, u, zeta, E, nu, m_visc, L_trunc):
    """sigma = A eps(v) + zeta Phi_L(B eps(u)) (Sections 1.6, 1.9): the Kelvin-Voigt stress."""
    return viscous_stress(v, E, nu, m_visc) + damaged_elastic_stress(u, zeta, E, nu, L_trunc)


def velocity_step_forms(v, w, u_old, zeta_old, E, nu, m_visc, L_trunc, f_B, f_N, dsN):
    """(a, l) of the velocity VI: a(v, w) = (A eps(v), eps(w)), l(w) = L_n(w) - elastic(w)."""
    a = ufl.inner(viscous_stress(v, E, nu, m_visc), eps(w)) * ufl.dx
    l = -ufl.inner(damaged_elastic_stress(u_old, zeta_old, E, nu, L_trunc), eps(w)) * ufl.dx
    L = load(w, f_B, f_N, dsN)
    return a, (l if L is None else l + L)
