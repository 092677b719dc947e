"""Section 3.3: dynamic, fully damageable frictionless contact, velocity step (3.159):

    (rho (v_n - v_{n-1})/k, w)_H + (zeta_n A eps(v_n), eps(w))_Q
        + (E(eps(u_{n-1}), zeta_{n-1}), eps(w))_Q + j(zeta_{n-1}, u_{n-1}, w) = <f_n, w>,

A = B / m_visc, E(eps, zeta) = eta_*(zeta) Phi_L(B eps) (3.111), j(zeta, u, w) =
int_{Gamma_C} eta_*(zeta) p_nu(u.nu - gap) w.nu ds (3.121) with p_nu(r) = c_nu r_+. The damage
scales the viscosity (with the NEW zeta_n, (3.159)), the elasticity and the contact pressure
(both with zeta_{n-1}). On K^h (zeta_star <= zeta <= 1 at the vertices) eta_*(zeta) = zeta,
so writing eta_* changes nothing in the scheme and keeps the forms meaningful for any input.

The non-thesis option ``elastic_term="implicit"`` (docs/models.md, section 3.3) evaluates the
elastic and contact forces at u_n = u_{n-1} + k v_n instead of u_{n-1}: unconditionally stable, for
fast qualitative runs only; the step is then nonlinear (semismooth in the contact term) and
returned as a residual. """
import ufl

from damage_dolfinx.forms.constitutive import B, Phi_L, eps, eta_star
from damage_dolfinx.forms.contact import positive_part

from damage_dolfinx.forms.elastic_damage import load

#: quadrature degree of the truncated (Phi_L, eta_*) and positive-part (contact) terms (the
#: thesis states none)
NONLINEAR_DEGREE = 2


def _measures(dsC):
    """(dx, dsC) with the quadrature degree of the non-polynomial terms."""
    metadata = {"quadrature_degree": NONLINEAR_DEGREE}
    return ufl.dx(metadata=metadata), dsC(metadata=metadata)


def damaged_viscous_stress(v, zeta, E, nu, m_visc, zeta_star):
    """eta_*(zeta) A eps(v), A = B / m_visc (3.111, 3.122)."""
    return eta_star(zeta, zeta_star) * B(eps(v), E, nu) / m_visc


def damaged_elastic_stress(u, zeta, E, nu, L_trunc, zeta_star):
    """E(eps(u), eta_*(zeta)) = eta_*(zeta) Phi_L(B eps(u)) (3.111, 2.106)."""
    return eta_star(zeta, zeta_star) * Phi_L(B(eps(u), E, nu), L_trunc)


def total_stress(v, u, zeta, E, nu, m_visc, L_trunc, zeta_star):
    """sigma_n = eta_*(zeta_n) (A eps(v_n) + Phi_L(B eps(u_n))) (3.111; von Mises, 1.9)."""
    return (damaged_viscous_stress(v, zeta, E, nu, m_visc, zeta_star)
            + damaged_elastic_stress(u, zeta, E, nu, L_trunc, zeta_star))


def damaged_contact_pressure(u, zeta, n, c_nu, gap, zeta_star):
    """eta_*(zeta) p_nu(u.nu - gap) = eta_*(zeta) c_nu (u.nu - gap)_+ (3.116)."""
    return eta_star(zeta, zeta_star) * c_nu * positive_part(ufl.dot(u, n) - gap)


def velocity_step_forms(v, w, v_old, u_old, zeta_new, zeta_old, rho, k, E, nu, m_visc, L_trunc,
                        zeta_star, c_nu, gap, n, f_B, f_N, dsN, dsC):
    """(a, l) of the linear system (3.159): v, w trial/test functions of V^h; v_old, u_old,
    zeta_old at step n-1, zeta_new = zeta_n from the damage step (3.158)."""
    dx = ufl.dx
    dxq, dsq = _measures(dsC)
    sigma_visc = damaged_viscous_stress(v, zeta_new, E, nu, m_visc, zeta_star)       # zeta_n A eps(v_n)
    sigma_el = damaged_elastic_stress(u_old, zeta_old, E, nu, L_trunc, zeta_star)   # E(eps(u_{n-1}), zeta_{n-1})
    p_c = damaged_contact_pressure(u_old, zeta_old, n, c_nu, gap, zeta_star)        # zeta_{n-1} p_nu(u_{n-1}.nu - g)
    a = (rho / k * ufl.inner(v, w) * dx              # (3.159) (rho delta v_n, w)_H, v_n part
         + ufl.inner(sigma_visc, eps(w)) * dx)        # (3.159) (zeta_n A eps(v_n), eps(w))_Q
    l = (rho / k * ufl.inner(v_old, w) * dx          # (3.159) (rho delta v_n, w)_H, v_{n-1} part
         - ufl.inner(sigma_el, eps(w)) * dxq          # (3.159) (E(eps(u_{n-1}), zeta_{n-1}), eps(w))_Q
         - p_c * ufl.dot(w, n) * dsq)                 # (3.159) j(zeta_{n-1}, u_{n-1}, w)
    L = load(w, f_B, f_N, dsN)                        # (3.159) <f_n, w>
    return a, (l if L is None else l + L)


def velocity_matrix_parts(v, w, rho, k, E, nu, m_visc):
    """(a_mass, a_visc(z)) with a(v, w) of (3.159) = a_mass + a_visc(zeta_n) for zeta_n in K^h
    (there eta_*(zeta_n) = zeta_n): a_visc is LINEAR in z, so the matrix of (3.159) is
    M_rho/k + sum_j zeta_n,j W_j, updated from the nodal zeta_n without re-assembly (3.3 module)."""
    a_mass = rho / k * ufl.inner(v, w) * ufl.dx                    # (3.159) (rho v_n / k, w)_H
    a_visc = lambda z: ufl.inner(z * B(eps(v), E, nu) / m_visc,  # noqa: E731
                                 eps(w)) * ufl.dx                  # (3.159) (zeta A eps(v_n), eps(w))_Q
    return a_mass, a_visc


def velocity_rhs_boundary(w, u_old, zeta_old, zeta_star, c_nu, gap, n, f_B, f_N, dsN, dsC):
    """The part of l of (3.159) that is not a matrix times a nodal vector: -j(zeta_{n-1},
    u_{n-1}, w) + <f_n, w>. With Phi_L = identity (L_trunc = inf) the rest of l is
    rho/k M v_{n-1} - K_B(zeta_{n-1}) u_{n-1}, K_B(z) = m_visc a_visc(z) (3.3 module)."""
    _, dsq = _measures(dsC)
    p_c = damaged_contact_pressure(u_old, zeta_old, n, c_nu, gap, zeta_star)
    l = -p_c * ufl.dot(w, n) * dsq                    # (3.159) j(zeta_{n-1}, u_{n-1}, w)
    L = load(w, f_B, f_N, dsN)                        # (3.159) <f_n, w>
    return l if L is None else l + L


def implicit_velocity_residual(v, w, v_old, u_old, zeta_new, zeta_old, rho, k, E, nu, m_visc,
                               L_trunc, zeta_star, c_nu, gap, n, f_B, f_N, dsN, dsC):
    """F(v; w) of the implicit deviation: (3.159) with u_{n-1} replaced by u_{n-1} + k v_n in the
    elastic and contact forces (damage factors still zeta_{n-1}); v is the unknown Function."""
    dx = ufl.dx
    dxq, dsq = _measures(dsC)
    u_new = u_old + k * v
    sigma_visc = damaged_viscous_stress(v, zeta_new, E, nu, m_visc, zeta_star)       # zeta_n A eps(v_n)
    sigma_el = damaged_elastic_stress(u_new, zeta_old, E, nu, L_trunc, zeta_star)   # at u_n
    p_c = damaged_contact_pressure(u_new, zeta_old, n, c_nu, gap, zeta_star)        # at u_n
    F = (rho / k * ufl.inner(v - v_old, w) * dx      # (3.159) (rho delta v_n, w)_H
         + ufl.inner(sigma_visc, eps(w)) * dx         # (3.159) (zeta_n A eps(v_n), eps(w))_Q
         + ufl.inner(sigma_el, eps(w)) * dxq          # (E(eps(u_n), zeta_{n-1}), eps(w))_Q
         + p_c * ufl.dot(w, n) * dsq)                 # j(zeta_{n-1}, u_n, w)
    L = load(w, f_B, f_N, dsN)                        # (3.159) <f_n, w>
    return F if L is None else F - L
