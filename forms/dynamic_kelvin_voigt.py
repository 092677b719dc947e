"""Section 3.1: dynamic Kelvin-Voigt body, frictionless normal compliance, velocity step (3.48):

    (rho (v_n - v_{n-1})/k, w) + (A eps(v_n), eps(w)) + (zeta_{n-1} Phi_L(B eps(u_{n-1})), eps(w))
        + int_{Gamma_C} p_nu(u_{n-1}.nu - gap) w.nu ds = L_n(w)          for all w in V^h,

A = B / m_visc, p_nu(r) = c_nu r_+. Inertia and viscosity implicit (a constant bilinear form for
a fixed k), the damaged truncated elastic force (2.106) and the contact force explicit, i.e. a
linear system with a fixed matrix (the thesis' (3.64) is this equation times k, up to its
misprints; docs/models.md, section 3.1).
"""
import ufl

from damage_dolfinx.numerics.constitutive import eps
from damage_dolfinx.numerics.contact import normal_compliance_pressure

from damage_dolfinx.forms.elastic_damage import load
from damage_dolfinx.forms.kelvin_voigt import damaged_elastic_stress, kelvin_voigt_stress, viscous_stress

#: quadrature degree of the truncated (Phi_L) and positive-part (contact) terms (the thesis
#: states none)
NONLINEAR_DEGREE = 2


#: sigma_n = A eps(v_n) + zeta_n Phi_L(B eps(u_n)) (Sections 1.6, 1.9)
total_stress = kelvin_voigt_stress


def velocity_step_forms(v, w, v_old, u_old, zeta_old, rho, k, E, nu, m_visc, L_trunc, c_nu, gap,
                        n, f_B, f_N, dsN, dsC):
    """(a, l) of (3.48): v, w trial/test functions of V^h; v_old, u_old, zeta_old at step n-1;
    rho, k, c_nu, gap numbers or fem.Constants; n the outward unit normal; dsC = None for no
    contact part."""
    dx = ufl.dx
    dxq = ufl.dx(metadata={"quadrature_degree": NONLINEAR_DEGREE})
    a = (rho / k * ufl.inner(v, w) * dx                                       # (3.48) (rho delta v_n, w)_H
         + ufl.inner(viscous_stress(v, E, nu, m_visc), eps(w)) * dx)          # (3.48) (A eps(v_n), eps(w))_Q
    l = (rho / k * ufl.inner(v_old, w) * dx                                   # (3.48) (rho v_{n-1}/k, w)_H
         - ufl.inner(damaged_elastic_stress(u_old, zeta_old, E, nu, L_trunc),
                     eps(w)) * dxq)                                           # (3.48) (E(eps(u_{n-1}), zeta_{n-1}), eps(w))_Q
    if dsC is not None:
        dsq = dsC(metadata={"quadrature_degree": NONLINEAR_DEGREE})
        l -= normal_compliance_pressure(u_old, n, c_nu, gap) * ufl.dot(w, n) * dsq  # (3.48) j(u_{n-1}, w)
    L = load(w, f_B, f_N, dsN)                                                # (3.48) <f_n, w>
    return a, (l if L is None else l + L)
