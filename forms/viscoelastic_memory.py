"""Section 2.3: quasistatic viscoelastic body with long memory and normal compliance.

Displacement step (2.137), with the memory M_n of (2.136) known:
    (B eps(u_n), eps(w)) + (M_n, eps(w)) + int_{Gamma_C} p_nu(u_n.nu - gap) w.nu ds = L_n(w).
The instantaneous part B is undamaged and untruncated (docs/models.md, section 2.3); M_n is built
from g(eps, zeta) = zeta Phi_L(B eps) (memory.py).
"""
import ufl

from damage_dolfinx.forms.constitutive import B, Phi_L, eps
from damage_dolfinx.forms.contact import normal_compliance_term

from damage_dolfinx.forms.elastic_damage import load


def memory_stress(u, E, nu, L_trunc):
    """Phi_L(B eps(u)), the stress factor of g (cell-wise constant for P1 u on simplices)."""
    return Phi_L(B(eps(u), E, nu), L_trunc)


def memory_integrand(u, zeta, E, nu, L_trunc):
    """g(eps(u), zeta) = zeta Phi_L(B eps(u)) (kernel G = a(t - s) g, Section 1.6)."""
    return zeta * memory_stress(u, E, nu, L_trunc)


def total_stress(u, M, E, nu):
    """sigma_n = B eps(u_n) + M_n."""
    return B(eps(u), E, nu) + M


def displacement_residual(u, w, M, E, nu, c_nu, gap, n, f_B, f_N, dsN, dsC):
    """F(u; w) of (2.137); u is the unknown Function."""
    F = (ufl.inner(total_stress(u, M, E, nu), eps(w)) * ufl.dx
         + normal_compliance_term(u, w, n, c_nu, gap, dsC))
    L = load(w, f_B, f_N, dsN)
    return F if L is None else F - L
