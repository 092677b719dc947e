"""3-D examples beyond the thesis (issue 17): the thesis models on 3-D meshes, same data.

The thesis is 2-D plane stress (PROBLEMS.md Section 0); these entries keep each example's data
and change only the body to a 3-D one, the elasticity to isotropic 3-D Hooke (whose plane-stress
reduction is B (2.36)) and the strain of the damage source to the full 3x3 strain.
"""
import math

import ufl

from ..examples import Example, Figure
from ..parameters import ModelParameters


def examples():
    from ..geometries.box_with_hole import box_with_hole
    from ..problems.elastic_2_1 import ElasticDamage

    ex1 = Example(
        id="2.1-ex1-3d", section="2.1",
        title="3-D: cube (0,5)^3 with a clamped cavity [2,3]^3, body force (50,25,0)t",
        params=ModelParameters(E=1e4, nu=0.33, kappa=1.0, zeta_star=0.01, q_star=1000.0,
                               variant="B", lam_D=0.1, lam_w=0.0, stop_at_zeta_star=True,
                               lam_u_plus=1000.0, lam_u_minus=100.0),
        T=1.0, k=0.02, n=10, dim=3, diameter=5 * math.sqrt(3),
        make_geometry=lambda comm, n, h: box_with_hole(comm, n),
        make_stepper=ElasticDamage,
        body_force=lambda x, t: ufl.as_vector((50.0 * t, 25.0 * t, 0.0)),
        assumptions=[
            "issue 17 (beyond the thesis): the 3-D counterpart of 2.1-ex1 with its data "
            "(E = 1e4, nu = 0.33, variant B, lam_D = 0.1, lam_u+ = 1000, lam_u- = 100, "
            "q_star = 1000, kappa = 1 (G1), zeta_star = 0.01, f_B = (50, 25, 0) t)",
            "3-D isotropic elasticity lambda tr(eps) I + 2 mu eps (its plane-stress reduction is "
            "B of (2.36)); the split of phi_B uses the eigenvalues of the 3x3 strain",
            "geometry: the square with hole becomes a cube with a cubic cavity, clamped on the "
            "cavity faces (Gamma_D), traction-free outside (Gamma_N)",
            "structured n x n x n grid (n multiple of 5), 6 tetrahedra per hexahedron; "
            "run defaults n = 10, k = 0.02",
            "solvers (scalable.py): elasticity CG + GAMG with the 6 rigid-body modes, damage "
            "CG + BoomerAMG, above 3000 unknowns; -mech_*/-damage_* options override",
            "1.9/G37 in 3-D: von Mises sqrt(3/2 dev(sigma):dev(sigma)), cell-wise (DG0)",
        ],
        figures=[Figure("fields_slices.png", "Example 2.1-1 in 3-D: von Mises stress and damage",
                        kind="slices")])
    return [ex1]
