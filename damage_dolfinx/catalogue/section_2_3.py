"""Catalogue entries of thesis Section 2.3 (viscoelastic body with long memory, frictionless
normal compliance, damage by the PDE (1.5), variant A)."""
import ufl

from damage_dolfinx.catalogue.examples import Example, Figure
from damage_dolfinx.geometries import GAMMA_C, GAMMA_D, GAMMA_N
from damage_dolfinx.core.parameters import ModelParameters


def examples():
    from damage_dolfinx.geometries.rectangle import rectangle, side

    def params(E, kernel):
        return ModelParameters(
            E=E, nu=0.3, kappa=1e-2, zeta_star=0.01, q_star=1000.0, variant="A", lam_D=1e-2,
            lam_u=10.0, lam_w=0.0, L_trunc=1000.0, stop_at_zeta_star=False,
            extra={"c_nu": 1e10, "gap": 0.0, "memory_kernel": kernel, "memory_amplitude":
                   1.0 if kernel == "constant" else -1.0, "memory_rate": 1.0,
                   "memory_mode": "auto"})

    common = [
        "departure (against the text): contact stiffness c_nu = 1e10 instead of the text's "
        "1/mu = 1e-10: (2.145), line 2161, states p_nu(r) = r_+/mu with mu = 1e10; we use mu "
        "as the stiffness (a near-rigid foundation), the text's p_nu is a foundation without "
        "resistance",
        "G12: gap = 0", "G15: variant A, q_star = 1000",
        "G16: instantaneous elasticity B undamaged and untruncated",
        "memory by the left rectangle rule (2.136), g = zeta Phi_L(B eps(u)) stored in DG1 tensors",
        "u_0 from the contact problem at t = 0 without memory (Remark 2.3)",
        "G43: no stop at zeta_star in Section 2.3 (flag stop_at_zeta_star off)",
        "1.9/G37: von Mises of the total stress B eps(u_n) + M_n, cell-wise (DG0)",
        "G40: fixed displacement factors (x3 Ex. 2, x2 Ex. 3) so that the figures at different "
        "times compare",
    ]
    ex1 = Example(
        name="2.3-ex1", section="2.3",
        title="unit square on a normal-compliance foundation, traction (-10,-10): convergence",
        params=params(100.0, "constant"), T=1.0, k=0.01, n=16, diameter=2 ** 0.5,
        mesh=lambda comm, n, h: rectangle(comm, (0, 0), (1, 1), n, n, {
            GAMMA_D: side(0, 0.0), GAMMA_C: side(1, 0.0), GAMMA_N: side(0, 1.0)}),
        model="2.3",
        traction=lambda x, t: ufl.as_vector((-10.0, -10.0)),
        assumptions=common + ["G10: structured n x n grid, diagonals right (nested meshes)",
                              "memory kernel G = zeta Phi_L(B eps) (constant in t - s): running sum"],
        figures=[Figure("figure_2_14.png", "Example 2.3-1: setting and mesh", kind="mesh"),
                 Figure("fields_final.png", "Example 2.3-1: von Mises stress and damage")],
        convergence=dict(ref_n=256, ref_k=5e-4, n=[4, 8, 16, 32, 64, 128],
                         k=[0.05, 0.02, 0.01, 0.005, 0.002, 0.001]))
    ex2 = Example(
        name="2.3-ex2", section="2.3",
        title="block (0,3)x(0,2) pushed by (-30,0) against a foundation on {0}x[0,1]: memory relaxation",
        params=params(1000.0, "constant"), T=2.0, k=0.01, n=10, diameter=13 ** 0.5,
        mesh=lambda comm, n, h: rectangle(comm, (0, 0), (3, 2), 3 * n, 2 * n, {
            GAMMA_D: side(1, 0.0), GAMMA_C: side(0, 0.0, 0.0, 1.0), GAMMA_N: side(0, 3.0)}),
        model="2.3",
        traction=lambda x, t: ufl.as_vector((-30.0, 0.0)),
        assumptions=common + ["G13: Omega = (0,3)x(0,2), load (-30,0) on {3}x[0,2], mesh 30x20 "
                              "(--n 10 = 10 cells per unit length), k = 0.01"],
        figures=[Figure("figure_2_16.png", "Example 2.3-2: setting and mesh", kind="mesh"),
                 Figure("figure_2_17.png", "Example 2.3-2: von Mises stress", fields=("von_mises",),
                        amplification=3.0, times=(0.0, 2.0)),
                 Figure("figure_2_18.png", "Example 2.3-2: damage", fields=("zeta",),
                        amplification=3.0)])
    ex3 = Example(
        name="2.3-ex3", section="2.3",
        title="cantilever (0,4)x(0,1) on a foundation, load (0,-10) removed at t = 0.5, fading memory",
        params=params(1000.0, "exponential"), T=1.0, k=0.01, n=20, diameter=17 ** 0.5,
        mesh=lambda comm, n, h: rectangle(comm, (0, 0), (4, 1), 4 * n, n, {
            GAMMA_D: side(0, 0.0), GAMMA_C: side(1, 0.0, 3.0, 4.0), GAMMA_N: side(1, 1.0)}),
        model="2.3",
        traction=lambda x, t: ufl.as_vector((0.0, ufl.conditional(ufl.le(t, 0.5 + 1e-12), -10.0, 0.0))),
        assumptions=common + ["G14: cantilever (0,4)x(0,1), Gamma_D = {0}x[0,1], Gamma_C = [3,4]x{0}, "
                              "load on the top face, mesh 80x20 (--n 20 = cells per unit length), k = 0.01",
                              "kernel G = -zeta exp(-(t-s)) Phi_L(B eps): recursive update",
                              "load (0,-10) for t <= 0.5 (t_n = 0.5 included), 0 afterwards"],
        figures=[Figure("figure_2_19.png", "Example 2.3-3: setting and mesh", kind="mesh"),
                 Figure("figure_2_20.png", "Example 2.3-3: von Mises stress", fields=("von_mises",),
                        amplification=2.0, times=(0.0, 0.5)),
                 Figure("figure_2_21.png", "Example 2.3-3: von Mises stress and damage",
                        amplification=2.0)])
    return [ex1, ex2, ex3]
