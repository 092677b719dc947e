"""Catalogue entry of thesis Section 2.1 Example 3: masonry arch bridge collapse (GitHub issue 3).

Data from the thesis: E = 5 GPa, nu = 0.49, density 2200 kg/m^3, k = 0.001 s, kappa = 1e-2,
zeta_star = 0.01, lam_D = 2e-3, lam_u = 5e9, lam_w = 7e-4; mesh of 8400 P1 triangles and 4515
nodes. Everything else (geometry, supports, load history, q_star, the meaning of the single
lam_u) is PROBLEMS.md G3, listed in ``assumptions``.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..examples import Example, Figure
from ..parameters import ModelParameters


@dataclass
class BridgeParameters(ModelParameters):
    """ModelParameters whose validate() also checks the bridge data in ``extra``."""

    def validate(self):
        from ..problems.bridge_2_1 import check_bridge_parameters
        super().validate()
        check_bridge_parameters(self.extra)
        return self


def examples():
    from ..geometries.bridge import RADIUS_CENTRE, THICKNESS, arch_bridge
    from ..problems.bridge_2_1 import BRIDGE_DEFAULTS, BridgeDamage

    params = BridgeParameters(
        E=5e9, nu=0.49, kappa=1e-2, zeta_star=0.01, q_star=1000.0, variant="B",
        lam_D=2e-3, lam_u_plus=5e9, lam_u_minus=5e9, lam_w=7e-4, stop_at_zeta_star=False,
        extra=dict(BRIDGE_DEFAULTS))
    ex3 = Example(
        id="2.1-ex3", section="2.1",
        title="masonry arch ring, self weight + quarter-span load P = load_rate t: collapse load "
              "and hinges",
        params=params, T=0.3, k=1e-3, h=0.05, diameter=2 * (RADIUS_CENTRE + THICKNESS / 2),
        make_geometry=lambda comm, n, h: arch_bridge(comm, h=h),
        make_stepper=BridgeDamage,
        assumptions=[
            "G3: semicircular ring, centre-line radius 15/pi = 4.775 m (centre line 15.0 m), "
            "thickness 0.70 m (intrados radius 4.425 m, clear span 8.85 m, rise 4.425 m); no "
            "fill, no abutments; plane stress, unit out-of-plane thickness",
            "G3: mapped n_r x n_theta = round(0.70/h) x round(15/h) grid, each quadrilateral cut "
            "by one fixed diagonal; h = 0.05 gives 14 x 300: 8400 triangles, 4515 nodes (the "
            "thesis's counts)",
            "G3: both springing faces clamped (Gamma_D); intrados and extrados traction free "
            "except the load patch",
            "G3: self weight f_B = (0, -2200*9.81) N/m^3 from t = 0; point load P(t) = load_rate*t "
            "(kN per metre) as a uniform downward traction P/|Gamma_N| on the extrados grid "
            "facets whose midpoints lie within +-0.05 m of the quarter-span abscissa "
            "x = -span/4 (a quarter of the clear span from the left springing)",
            "G3: load_rate = 1000 kN/s (1 kN per step at k = 0.001), T = 0.3 s; NOT calibrated: "
            "the failure load is a result of the model, compared with the thesis's 90 kN",
            "G3: the single lambda_u of the thesis read as lam_u_plus = lam_u_minus = 5e9 "
            "(variant B); tension-only damage with --set lam_u_minus=0",
            "G3: q_star = 1000 (inactive: strains stay far below sqrt(1000))",
            "G43/G3: stop_at_zeta_star off; the run stops at collapse = first step at which all "
            "nodes of one radial grid line (cross-section) have zeta <= zeta_star; failure load "
            "= P at that step (resolution: one load increment load_rate*k)",
            "hinges: local maxima of the damaged depth of the sections (fraction of nodes with "
            "zeta <= hinge_zeta = 0.5) that reach hinge_depth = 0.5, merged within one ring "
            "thickness; the face (intrados/extrados) where damage is deeper is reported",
            "force-displacement curve: P against the mean vertical displacement of the load "
            "patch (history.csv columns P_kN, u_load_y; assumed content of Figure 2.7)",
            "G4/G38: scheme (2.20)-(2.21) as in Examples 1-2, quadrature degree 2 for the source",
            "1.9/G37: von Mises = plane-stress value of eta_*(zeta) B eps(u), cell-wise (DG0)",
        ],
        figures=[Figure("figure_2_6.png", "Example 2.1-3: arch ring, supports and load patch",
                        kind="mesh"),
                 Figure("figure_2_8.png", "Example 2.1-3: von Mises stress at failure",
                        fields=("von_mises",), amplification=50.0),
                 Figure("figure_2_9.png", "Example 2.1-3: damage at failure",
                        fields=("zeta",), amplification=50.0)])
    return [ex3]
