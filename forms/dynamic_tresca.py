"""Section 3.2: dynamic Kelvin-Voigt body, bilateral contact, Tresca friction, velocity step (3.95):

    (rho (v_n - v_{n-1})/k, w - v_n) + (A eps(v_n), eps(w - v_n)) + j(w) - j(v_n)
        >= L_n(w - v_n) - (eta_*(zeta_{n-1}) Phi_L(B eps(u_{n-1})), eps(w - v_n)),

A = B / m_visc; inertia and viscosity implicit, the damaged truncated elastic force explicit
(eta_*(zeta), not zeta, in the elastic operator of Section 3.2; docs/models.md, section 3.2).
Written as the second-kind VI a(v, w - v) + j(w) - j(v) >= l(w - v) that
``friction.FrictionProblem`` takes.
"""
import ufl

from damage_dolfinx.forms.constitutive import B, Phi_L, eps, eta_star

from damage_dolfinx.forms.elastic_damage import load
from damage_dolfinx.forms.kelvin_voigt import viscous_stress


def elastic_stress(u, zeta, E, nu, L_trunc, zeta_star):
    """E(eps(u), zeta) = eta_*(zeta) Phi_L(B eps(u)) (Section 3.2, (2.106) with eta_*)."""
    return eta_star(zeta, zeta_star) * Phi_L(B(eps(u), E, nu), L_trunc)


def total_stress(v, u, zeta, E, nu, m_visc, L_trunc, zeta_star):
    """sigma_n = A eps(v_n) + E(eps(u_n), zeta_n) (von Mises output; docs/models.md, "Output
    conventions")."""
    return viscous_stress(v, E, nu, m_visc) + elastic_stress(u, zeta, E, nu, L_trunc, zeta_star)


def velocity_step_forms(v, w, v_old, u_old, zeta_old, rho, k, E, nu, m_visc, L_trunc, zeta_star,
                        f_B, f_N, dsN):
    """(a, l) of (3.95): v, w trial/test functions of V^h; v_old, u_old, zeta_old at step n-1;
    rho, k numbers or fem.Constants."""
    dx = ufl.dx
    E_old = elastic_stress(u_old, zeta_old, E, nu, L_trunc, zeta_star)  # E(eps(u_n-1), zeta_n-1)
    a = (rho / k * ufl.inner(v, w) * dx                               # (3.95) rho (v_n/k, w)_H
         + ufl.inner(viscous_stress(v, E, nu, m_visc), eps(w)) * dx)  # (3.95) (A eps(v_n), eps(w))
    l = (rho / k * ufl.inner(v_old, w) * dx                           # (3.95) rho (v_n-1/k, w)_H
         - ufl.inner(E_old, eps(w)) * dx)                             # (3.95) (E_old, eps(w))_Q
    L = load(w, f_B, f_N, dsN)                                        # (3.95) <f_n, w>
    return a, (l if L is None else l + L)
