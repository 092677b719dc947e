"""Catalogue entries of thesis Section 2.1 (quasistatic elastic body with damage)."""
import math

import ufl

from damage_dolfinx.catalogue.examples import Example, Figure
from damage_dolfinx.core.parameters import ModelParameters


def examples():
    from damage_dolfinx.geometries.disc_minus_diamond import disc_minus_diamond
    from damage_dolfinx.geometries.square_with_hole import square_with_hole

    common = dict(E=1e4, nu=0.33, kappa=1.0, zeta_star=0.01, q_star=1000.0, variant="B",
                  lam_D=0.1, lam_w=0.0, stop_at_zeta_star=True)
    common_assumptions = [
        "G1: kappa missing in the thesis -> kappa = 1 (kappa = 1e-2 drives zeta far below "
        "zeta_star at the hole corners, contradicting the thesis text)",
        "G4: scheme implemented exactly as (2.20)-(2.21): implicit diffusion, source from step n-1, "
        "elasticity with the new damage eta_*(zeta_n)",
        "G38: quadrature degree 2 for the damage source",
        "G43: the run stops when min zeta_n <= zeta_star (stop_at_zeta_star)",
        "1.9/G37: von Mises = plane-stress value of eta_*(zeta) B eps(u), cell-wise (DG0)",
    ]
    ex1 = Example(
        name="2.1-ex1", section="2.1",
        title="square (0,5)^2 with clamped hole [2,3]^2, body force (50,25)t: convergence example",
        params=ModelParameters(**common, lam_u_plus=1000.0, lam_u_minus=100.0),
        T=1.0, k=0.01, n=20, diameter=5 * math.sqrt(2),
        mesh=lambda comm, n, h: square_with_hole(comm, n),
        model="2.1",
        body_force=lambda x, t: ufl.as_vector((50.0 * t, 25.0 * t)),
        assumptions=common_assumptions + [
            "G10: structured n x n grid, diagonals 'right', hole cells removed (nested meshes)",
            "run defaults n = 20, k = 0.01 (quick); the thesis study uses reference n = 160, k = 5e-4"],
        figures=[Figure("figure_2_1.png", "Example 2.1-1: setting and mesh", kind="mesh"),
                 Figure("fields_final.png", "Example 2.1-1: von Mises stress and damage")],
        convergence=dict(ref_n=160, ref_k=5e-4, n=[5, 10, 20, 40, 80],
                         k=[0.05, 0.02, 0.01, 0.005, 0.002, 0.001]))

    def ex2(letter, lam_plus, lam_minus, figure, kind):
        return Example(
            name=f"2.1-ex2{letter}", section="2.1",
            title=f"disc |x|<4 minus diamond, clockwise traction (5y,-5x)t: {kind} damage only",
            params=ModelParameters(**common, lam_u_plus=lam_plus, lam_u_minus=lam_minus),
            T=1.0, k=0.01, h=0.1, diameter=8.0,
            mesh=lambda comm, n, h: disc_minus_diamond(comm, h=h, h_corner=h / 2),
            model="2.1",
            traction=lambda x, t: ufl.as_vector((5.0 * x[1] * t, -5.0 * x[0] * t)),
            assumptions=common_assumptions + [
                "G2: Gamma_D = inner diamond |x1|+|x2| = 1 (clamped), Gamma_N = circle",
                "G2: gmsh h = 0.1 (h/2 = 0.05 near the diamond corners), k = 0.01",
                "G1: kappa = 1 in Example 2 as well (the thesis gives no kappa for Examples 1-2; "
                "kappa = 1e-2, the value of Example 3, with --set kappa=0.01)"],
            # the mesh (Figure 2.3) is the same for both cases: drawn once, by case a
            figures=([Figure("figure_2_3.png", "Example 2.1-2: setting and mesh", kind="mesh")]
                     if letter == "a" else [])
            + [Figure(figure, f"Example 2.1-2 ({kind} damage only): von Mises stress and damage")])

    return [ex1,
            ex2("a", 1000.0, 0.0, "figure_2_4.png", "tension"),
            ex2("b", 0.0, 1000.0, "figure_2_5.png", "compression")]
