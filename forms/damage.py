"""Discrete damage step shared by all seven schemes (docs/models.md, "The damage step").

b(z, xi) = (z, xi) + k kappa (grad z, grad xi),  l(xi) = (zeta_old, xi) + k (phi_old, xi):
the PDE form (1.5) solves b(zeta_n, .) = l; the obstacle form solves the VI over
K^h = {zeta_star <= xi <= 1}.
"""
import ufl

#: quadrature degree of the non-polynomial damage source (not stated in the thesis)
SOURCE_DEGREE = 2


def damage_step_forms(zeta, xi, zeta_old, phi_old, k, kappa):
    """(a, L) of the implicit damage step: zeta and xi are trial/test functions of B^h."""
    dx = ufl.dx
    a = zeta * xi * dx + k * kappa * ufl.inner(ufl.grad(zeta), ufl.grad(xi)) * dx
    L = zeta_old * xi * dx
    source = k * phi_old * xi
    if not isinstance(source, ufl.constantvalue.Zero):  # phi = 0 (e.g. all lambdas zero)
        L += source * dx(metadata={"quadrature_degree": SOURCE_DEGREE})
    return a, L
