"""Contact laws (PROBLEMS.md 1.5) as UFL expressions.

Normal compliance, frictionless: -sigma_nu = p_nu(u_nu - gap), p_nu(r) = c_nu r_+; its weak term
int_{Gamma_C} p_nu(u.nu - gap) w.nu ds is semismooth, Newton uses the UFL derivative
(c_nu times the indicator of penetration).
"""
import ufl


def positive_part(r):
    """r_+ = max(r, 0)."""
    return ufl.max_value(r, 0.0)


def normal_compliance_pressure(u, n, c_nu, gap=0.0):
    """p_nu(u.nu - gap) = c_nu (u.nu - gap)_+ (penetration is u.nu > gap)."""
    return c_nu * positive_part(ufl.dot(u, n) - gap)


def normal_compliance_term(u, w, n, c_nu, gap, dsC):
    """int_{Gamma_C} p_nu(u.nu - gap) w.nu ds."""
    return normal_compliance_pressure(u, n, c_nu, gap) * ufl.dot(w, n) * dsC
