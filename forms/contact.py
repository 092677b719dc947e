"""Contact laws (docs/models.md, "Normal compliance" and "Tresca friction") as UFL expressions.

Normal compliance, frictionless: -sigma_nu = p_nu(u_nu - gap), p_nu(r) = c_nu r_+; its weak term
int_{Gamma_C} p_nu(u.nu - gap) w.nu ds is semismooth, Newton uses the UFL derivative
(c_nu times the indicator of penetration).
"""
import ufl

from damage_dolfinx import compat


def positive_part(r):
    """r_+ = max(r, 0)."""
    return ufl.max_value(r, 0.0)


def normal_compliance_pressure(u, n, c_nu, gap=0.0):
    """p_nu(u.nu - gap) = c_nu (u.nu - gap)_+ (penetration is u.nu > gap)."""
    return c_nu * positive_part(ufl.dot(u, n) - gap)


def normal_compliance_term(u, w, n, c_nu, gap, dsC):
    """int_{Gamma_C} p_nu(u.nu - gap) w.nu ds."""
    return normal_compliance_pressure(u, n, c_nu, gap) * ufl.dot(w, n) * dsC


# ------------------------------------------------------------------ Tresca friction (1.5)
#: Facet quadrature at the vertices (trapezoidal rule, GLL degree 1): the friction functional
#: j(w) = int g |w_tau| ds becomes the nodal sum sum_i m_i g_i |w_tau,i| (lumped boundary mass).
#: All three friction solvers use this same discrete j, so they solve the same discrete problem.
NODAL_QUADRATURE = {"quadrature_rule": "GLL", "quadrature_degree": 1}
#: the same vertex rule on the triangular faces of a tetrahedral mesh (3-D; the
#: metadata depends on the FFCx version: compat.facet_vertex_quadrature)
NODAL_QUADRATURE_3D = compat.facet_vertex_quadrature()


def tangent(n):
    """Unit tangent tau = (-nu_2, nu_1)."""
    return ufl.as_vector((-n[1], n[0]))


def clip(x, lo, hi):
    return ufl.max_value(lo, ufl.min_value(hi, x))


def Phi_reg(r, g, eps_reg):
    """Regularised friction law (2.99): Phi_eps(r) = g max(-1, min(1, r/eps))."""
    return g * clip(r / eps_reg, -1.0, 1.0)


def F_reg(r, g, eps_reg):
    """Its potential (2.101): g r^2/(2 eps) for |r| <= eps, g |r| - g eps/2 otherwise."""
    return ufl.conditional(ufl.le(abs(r), eps_reg), g * r**2 / (2.0 * eps_reg),
                           g * abs(r) - g * eps_reg / 2.0)


# ---------------------------------------- Tresca friction in 3-D: a tangent plane
def tangential_part(v, n):
    """v_tau = v - (v.nu) nu, the tangential part of a vector (any dimension)."""
    return v - ufl.dot(v, n) * n


def _bounded_norm(r, eps_reg):
    """max(|r|, eps) written as sqrt(max(|r|^2, eps^2)): its UFL derivative is finite at r = 0."""
    return ufl.sqrt(ufl.max_value(ufl.dot(r, r), eps_reg**2))


def Phi_reg_vector(r, g, eps_reg):
    """(2.99) for a tangential vector r: Phi_eps(r) = g r / max(|r|, eps), i.e. g times the
    projection of r/eps onto the unit disc; for a scalar r it is Phi_reg."""
    return g * r / _bounded_norm(r, eps_reg)


def F_reg_vector(r, g, eps_reg):
    """Its potential: g |r|^2/(2 eps) for |r| <= eps, g |r| - g eps/2 otherwise."""
    return ufl.conditional(ufl.le(ufl.dot(r, r), eps_reg**2), g * ufl.dot(r, r) / (2.0 * eps_reg),
                           g * _bounded_norm(r, eps_reg) - g * eps_reg / 2.0)
