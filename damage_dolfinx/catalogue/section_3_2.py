"""Catalogue entries of thesis Section 3.2 (dynamic Kelvin-Voigt body, bilateral contact, Tresca
friction, damage inclusion with variant A; scheme (3.94)-(3.96))."""
import math

import numpy as np
import ufl

from damage_dolfinx.catalogue.examples import Example, Figure, Reading
from damage_dolfinx.geometries import GAMMA_C, GAMMA_D, GAMMA_N
from damage_dolfinx.core.parameters import ModelParameters
from damage_dolfinx.catalogue.section_2_2 import OMEGA_PD, RHO_UZAWA


def _params(g_fric, solver="newton"):
    """Data common to the three examples (thesis 3.2.3): E = 1e4, nu = 0.3, rho = 1, A = B/100,
    kappa = 1, lam_D = 0, lam_u = 1000, lam_w = 0, zeta_star = 0.01."""
    return ModelParameters(
        E=1e4, nu=0.3, kappa=1.0, zeta_star=0.01, q_star=1000.0, variant="A", lam_D=0.0,
        lam_u=1000.0, lam_w=0.0, L_trunc=1000.0, stop_at_zeta_star=False,
        extra={"rho": 1.0, "m_visc": 100.0, "g_fric": g_fric, "eps_reg": 1e-9,
               "friction_solver": solver, "rho_uzawa": RHO_UZAWA, "omega_pd": OMEGA_PD,
               "friction_tol": 1e-6, "stability_check": "warn"})


def _on(axis, value):
    """Marker of the contact nodes on the line x_axis = value (history columns)."""
    return lambda X: np.isclose(X[axis], value, atol=1e-10)


#: evidence reading of Example 1, the default (benchmarks/readings.md)
EVIDENCE_EX1 = Reading(
    overrides={"kappa": 0.003, "lam_u": 2000.0},
    assumptions=[
        "R1 (evidence reading; FITTED value): kappa = 0.003 instead of kappa = 1 (line 3973). "
        "With kappa = 1 the damage is smoothed over the whole square (zeta 0.81-0.85 at t = 1), "
        "the spatial error is tiny and the error falls with k, not n: Table 3.2 (lines "
        "3958-3963) falls with n and is flat in k (thesis-size literal study: 0.007-0.54x the "
        "thesis, fitted rate 0.41 against 1.05). No line of the text states 0.003: the thesis "
        "states kappa = 1 in every Chapter 3 example (lines 3329, 3365, 3393, 3973, 4438) and "
        "1e-2 in Sections 2.1 Ex. 3 and 2.3 (lines 1131, 2157). 0.003 is the largest kappa "
        "tried (1, 1e-2, 3e-3, 1e-3) that, with R2, puts every cell of Table 3.2 within 2x: at "
        "thesis size kappa = 1e-2 gives 0.30-0.79x (rate 1.14), 3e-3 gives 0.51-0.81x (median "
        "0.58, rate 1.04 against 1.05); at reduced size 1e-3 gives 0.56-0.81x (rate 0.90 "
        "against 0.95), so Table 3.2 fixes kappa only to a few 1e-3",
        "R2 (evidence reading; taken from another example of the text): lambda_u = 2000 instead of 1000 (line 3973), the value the "
        "thesis states for the next section's convergence example (3.3 Example 1, line 4438). "
        "Without it the error stays 2.5-16x below Table 3.2 whatever kappa (reduced size: "
        "kappa = 1e-2 0.06-0.37x, 3e-3 0.12-0.38x, 1e-3 0.16-0.39x); with it but kappa = 1 the "
        "shape stays wrong (0.04-0.55x, rate 0.72). It is not a missing 1/2 of (1.3) in the "
        "thesis code: every statement of (1.3)-(1.4) carries the 1/2 (lines 349, 365, 383-389). "
        "Doubling lambda_u everywhere would nearly double our 2.1-ex1 and 3.3-ex1 errors "
        "(+81-110 %, +94-97 %); the thesis's tables of those two examples are not available to "
        "this project, so they are not compared"])


def examples():
    from damage_dolfinx.geometries.rectangle import rectangle, side
    from damage_dolfinx.geometries.slope import slope_block

    common = [
        "G22: q_star = 1000 (Chapter 3 value; Section 3.2 lists none), L_trunc = 1000",
        "elastic operator and damage source with eta_*(zeta) (3.2); the obstacle step keeps "
        "zeta in [zeta_star, 1], where eta_*(zeta) = zeta",
        "G29: friction solved as in 2.2: Newton on Phi_eps with eps_reg = 1e-9 (warm start, eps "
        "continuation only on failure); Uzawa and penalty-duality available "
        "(--set friction_solver=...); Uzawa refused without Gamma_D (see Example 2)",
        "friction functional integrated by the vertex (trapezoidal) rule: a nodal Tresca law",
        "u_0 = 0, v_0 = 0, zeta_0 = 1 (thesis data)",
        "1.9/G37: von Mises of the total stress A eps(v_n) + eta_*(zeta_n) Phi_L(B eps(u_n)), DG0",
        "1.8: the explicit elastic force limits k (about 0.02 for m_visc = 100); checked at start "
        "(stability_check = warn | error | off)",
    ]
    square = lambda comm, n, h: rectangle(comm, (0, 0), (1, 1), n, n, {  # noqa: E731
        GAMMA_D: side(0, 1.0), GAMMA_N: side(0, 0.0), GAMMA_C: side(1, 0.0)})
    ex1 = Example(
        name="3.2-ex1", section="3.2", readings={"evidence": EVIDENCE_EX1},
        default_reading="evidence",
        title="unit square, traction (200,0)(e^t - 1) on {0}x[0,1], Tresca g = 5: convergence "
              "(Table 3.2)",
        params=_params(5.0), T=1.0, k=0.01, n=16, diameter=math.sqrt(2),
        mesh=square, model="3.2",
        traction=lambda x, t: ufl.as_vector((200.0 * (ufl.exp(t) - 1.0), 0.0)),
        builders={"contact_faces": {"bottom": _on(1, 0.0)}},
        assumptions=common + [
            "Gamma_D = {1}x[0,1], f_N on Gamma_N = {0}x[0,1], Gamma_C = [0,1]x{0}, top free "
            "(thesis Figure 3.9)",
            "G10: nested structured meshes, diagonals right",
            "error (3.109): max_n ||u_n - u_n^hk||_L2 + ||zeta_n - zeta_n^hk||_L2 against "
            "n = 128, k = 5e-4"],
        figures=[Figure("figure_3_9.png", "Example 3.2-1: setting and mesh", kind="mesh"),
                 Figure("fields_final.png", "Example 3.2-1: von Mises stress and damage")],
        convergence=dict(ref_n=128, ref_k=5e-4, n=[4, 8, 16, 32, 64],
                         k=[0.02, 0.01, 0.005, 0.002, 0.001]))

    ex2 = Example(
        name="3.2-ex2", section="3.2",
        title="block (0,4)x(0,2) between two frictional planes (g = 1 above, 1000 below), "
              "f_B = (40,0) sin(1.5 pi t)",
        params=_params(1.0), T=3.0, k=0.005, n=20, diameter=math.hypot(4, 2),
        mesh=lambda comm, n, h: rectangle(comm, (0, 0), (4, 2), 4 * n, 2 * n, {
            GAMMA_C: lambda x: side(1, 0.0)(x) | side(1, 2.0)(x)}),
        model="3.2",
        body_force=lambda x, t: ufl.as_vector((40.0 * ufl.sin(1.5 * math.pi * t), 0.0)),
        builders={"friction_bound": lambda x: ufl.conditional(ufl.gt(x[1], 1.0), 1.0, 1000.0),
                  "contact_faces": {"top": _on(1, 2.0), "bottom": _on(1, 0.0)}},
        assumptions=common + [
            "G31: mesh 80x40 (n = 20 cells per unit length, --n), k = 0.005",
            "G42: Gamma_D empty; each step is well posed through the mass term (inertia) and "
            "the bottom bound g = 1000 is never reached",
            "history: u_tau_max_top / u_tau_max_bottom = max |u_tau| over the contact nodes "
            "of each face",
            "friction solvers: Newton (default) and penalty-duality agree (4.9e-7 relative in u "
            "at t = 0.4); Uzawa is refused: although the mass "
            "term makes a coercive, the ||eps(.)|| stopping test of friction.py does not see "
            "rigid translations (in runs: it stops after one iteration at n = 4, never at n = 20)"],
        figures=[Figure("figure_3_10.png", "Example 3.2-2: setting and mesh", kind="mesh"),
                 Figure("figure_3_11.png", "Example 3.2-2: deformed mesh", fields=("zeta",),
                        amplification=5.0, mesh_lines=True),
                 Figure("figure_3_12.png", "Example 3.2-2: von Mises stress and damage",
                        amplification=5.0),  # the factor of its pair 3.11 (thesis line 3998)
                 Figure("figure_3_11_history.png", "Example 3.2-2: tangential displacements",
                        kind="history",
                        fields=(("u_tau_max_top", "max |u_tau| top (g = 1) [m]"),
                                ("u_tau_max_bottom", "max |u_tau| bottom (g = 1000) [m]")))])

    ex3 = Example(
        name="3.2-ex3", section="3.2",
        title="block on a 45-degree slope held by an obstacle, gravity 40(e^t - 1), Tresca g = 1",
        params=_params(1.0), T=1.0, k=0.005, n=20, diameter=math.hypot(2, 1),
        mesh=lambda comm, n, h: slope_block(comm, n),
        model="3.2",
        body_force=lambda x, t: -20.0 * math.sqrt(2) * (ufl.exp(t) - 1.0) * ufl.as_vector((1.0, 1.0)),
        builders={"contact_faces": {"plane": _on(1, 0.0), "obstacle": _on(0, 0.0)}},
        assumptions=common + [
            "G30: Omega = (0,2)x(0,1) in axes aligned with the slope (x_1 up the slope); "
            "Gamma_C = bottom (plane) and left side (obstacle), both bilateral with Tresca "
            "g = 1; Gamma_D empty; top and right sides free; drawn in the slope-aligned frame",
            "G31: mesh 40x20 (n = 20 cells per unit length, --n), k = 0.005",
            "G40: amplification of Figure 3.13 not given: largest displacement = 10% of the "
            "diameter"],
        figures=[Figure("figure_3_13_left.png", "Example 3.2-3: setting and mesh", kind="mesh"),
                 Figure("figure_3_13.png", "Example 3.2-3: deformed mesh", fields=("zeta",),
                        mesh_lines=True),
                 Figure("figure_3_14.png", "Example 3.2-3: von Mises stress and damage")])
    return [ex1, ex2, ex3]
