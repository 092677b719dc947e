"""Section 3.1: dynamic Kelvin-Voigt body, frictionless normal compliance, velocity step (3.48):

    (rho (v_n - v_{n-1})/k, w) + (A eps(v_n), eps(w)) + (zeta_{n-1} Phi_L(B eps(u_{n-1})), eps(w))
        + int_{Gamma_C} p_nu(u_{n-1}.nu - gap) w.nu ds = L_n(w)          for all w in V^h,

A = B / m_visc, p_nu(r) = c_nu r_+. Inertia and viscosity implicit (a constant bilinear form for
a fixed k), the damaged truncated elastic force (2.106) and the contact force explicit, i.e. a
linear system with a fixed matrix (the thesis' (3.64) is this equation times k, up to its
misprints; docs/models.md, section 3.1).

Quadrature: with P1 u, zeta on an affine simplex mesh (every mesh of the package but
quadrilaterals and curved cells), eps(u_{n-1}), B eps(u_{n-1}), its truncation Phi_L and eps(w)
are constant on each cell and zeta_{n-1} is linear, so the elastic term's integrand is linear and
the one-point rule (degree 1) integrates it exactly; elsewhere it gets NONLINEAR_DEGREE. The
contact term's positive part is not polynomial on a facet: NONLINEAR_DEGREE always.
"""
import ufl

from damage_dolfinx import compat
from damage_dolfinx.forms.constitutive import eps
from damage_dolfinx.forms.contact import normal_compliance_pressure

from damage_dolfinx.forms.elastic_damage import load
from damage_dolfinx.forms.kelvin_voigt import damaged_elastic_stress, kelvin_voigt_stress, viscous_stress

#: quadrature degree of the positive-part (contact) term, and of the truncated (Phi_L) elastic
#: term where it is not linear on a cell (the thesis states none)
NONLINEAR_DEGREE = 2


def elastic_degree(u_old, zeta_old) -> int:
    """Quadrature degree of (zeta_{n-1} Phi_L(B eps(u_{n-1})), eps(w)): 1 (exact, the integrand
    is linear) for P1 u and zeta on an affine simplex mesh, NONLINEAR_DEGREE otherwise."""
    V, Z = (getattr(f, "function_space", None) for f in (u_old, zeta_old))
    if V is not None and Z is not None and compat.element_degree(V) == 1 \
            and compat.element_degree(Z) == 1 and compat.affine_simplex(V.mesh):
        return 1
    return NONLINEAR_DEGREE


def inertia_form(v, w, rho, k):
    """(rho v / k, w)_H: the matrix's inertia part, and with v = v_{n-1} the right-hand side's
    (rho v_{n-1}/k, w)_H (which ``velocity_step_forms(..., inertia_rhs=False)`` leaves out, for
    a solver that adds it as M_rho/k v_{n-1})."""
    return rho / k * ufl.inner(v, w) * ufl.dx


#: sigma_n = A eps(v_n) + zeta_n Phi_L(B eps(u_n)) (Sections 1.6, 1.9)
total_stress = kelvin_voigt_stress


def velocity_step_forms(v, w, v_old, u_old, zeta_old, rho, k, E, nu, m_visc, L_trunc, c_nu, gap,
                        n, f_B, f_N, dsN, dsC, inertia_rhs=True):
    """(a, l) of (3.48): v, w trial/test functions of V^h; v_old, u_old, zeta_old at step n-1;
    rho, k, c_nu, gap numbers or fem.Constants; n the outward unit normal; dsC = None for no
    contact part; ``inertia_rhs=False``: l without (rho v_{n-1}/k, w)_H (see inertia_form)."""
    dx = ufl.dx
    dxe = ufl.dx(metadata={"quadrature_degree": elastic_degree(u_old, zeta_old)})
    a = (inertia_form(v, w, rho, k)                                           # (3.48) (rho delta v_n, w)_H
         + ufl.inner(viscous_stress(v, E, nu, m_visc), eps(w)) * dx)          # (3.48) (A eps(v_n), eps(w))_Q
    l = -ufl.inner(damaged_elastic_stress(u_old, zeta_old, E, nu, L_trunc),
                   eps(w)) * dxe                                              # (3.48) (E(eps(u_{n-1}), zeta_{n-1}), eps(w))_Q
    if inertia_rhs:
        l = inertia_form(v_old, w, rho, k) + l                                # (3.48) (rho v_{n-1}/k, w)_H
    if dsC is not None:
        dsq = dsC(metadata={"quadrature_degree": NONLINEAR_DEGREE})
        l -= normal_compliance_pressure(u_old, n, c_nu, gap) * ufl.dot(w, n) * dsq  # (3.48) j(u_{n-1}, w)
    L = load(w, f_B, f_N, dsN)                                                # (3.48) <f_n, w>
    return a, (l if L is None else l + L)
