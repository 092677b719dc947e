"""3-D examples beyond the thesis: the thesis models on 3-D meshes, same data.

The thesis is 2-D plane stress (docs/models.md, "Common notation"); these entries keep each
example's data and change only the body to a 3-D one, the elasticity to isotropic 3-D Hooke (whose
plane-stress reduction is B (2.36)) and the strain of the damage source to the full 3x3 strain. """
import dataclasses
import math

import ufl

from damage_dolfinx.catalogue.examples import Example, Figure
from damage_dolfinx.geometries import GAMMA_C, GAMMA_D, GAMMA_N
from damage_dolfinx.core.parameters import ModelParameters

#: 3-D contact examples (benchmarks/reference_output/contact_3d/): default mesh sizes and
#: time steps; the k of the explicit dynamic schemes is at most 0.8 k_max of stability.py at the
#: default mesh (computed, listed in each entry's assumptions)
N_2_3_EX1, N_3_1_EX1, N_3_3_EX1 = 8, 12, 12
K_3_1_EX1 = 0.01
#: the wrench plate: gmsh size h (h/2 on the hexagon faces), time step, default final time
H_3_3_EX3, K_3_3_EX3, T_3_3_EX3 = 0.2, 1.0e-5, 0.05


def _thesis_entry(section_module, example_id):
    """The 2-D catalogue entry whose data a 3-D example keeps."""
    import importlib
    module = importlib.import_module(f"{__package__}.{section_module}")
    return next(ex for ex in module.examples() if ex.id == example_id)


def _from_2d(ex2d, **changes):
    """A 3-D entry with the data of ``ex2d``: its parameters, time grid and reading; geometry,
    loads, figures and assumptions replaced; no convergence study (a 3-D reference at n = 256
    is out of reach)."""
    changes.setdefault("assumptions", [])
    changes["assumptions"] = (
        [f"beyond the thesis: the 3-D counterpart of {ex2d.id} with its data; its "
         "2-D assumptions follow (marked '2-D:'), the geometry, mesh and time-step lines among "
         "them superseded by the 3-D lines after them"]
        + [f"2-D: {a}" for a in ex2d.assumptions] + changes["assumptions"])
    return dataclasses.replace(ex2d, dim=3, convergence=None, literal=None, reading=None,
                               **changes)


_3D_COMMON = [
    "3-D isotropic elasticity lambda tr(eps) I + 2 mu eps (its plane-stress reduction is B of "
    "(2.36)); Phi_L componentwise on the 3x3 tensor; the split of phi uses the eigenvalues of "
    "the 3x3 strain",
    "normal compliance p_nu(u.nu - gap) = c_nu (u.nu - gap)_+ on a plane face of the box "
    "(nu its outward normal), frictionless: the same weak term as in 2-D",
    "1.9/G37 in 3-D: von Mises sqrt(3/2 dev(sigma):dev(sigma)), cell-wise (DG0)",
    "figures: sections through the body (slices.py); XDMF of u, zeta, von Mises for ParaView",
]


def examples():
    from damage_dolfinx.geometries.box_with_hole import box_with_hole

    ex1 = Example(
        name="2.1-ex1-3d", section="2.1",
        title="3-D: cube (0,5)^3 with a clamped cavity [2,3]^3, body force (50,25,0)t",
        params=ModelParameters(E=1e4, nu=0.33, kappa=1.0, zeta_star=0.01, q_star=1000.0,
                               variant="B", lam_D=0.1, lam_w=0.0, stop_at_zeta_star=True,
                               lam_u_plus=1000.0, lam_u_minus=100.0),
        T=1.0, k=0.02, n=10, dim=3, diameter=5 * math.sqrt(3),
        mesh=lambda comm, n, h: box_with_hole(comm, n),
        model="2.1",
        body_force=lambda x, t: ufl.as_vector((50.0 * t, 25.0 * t, 0.0)),
        assumptions=[
            "beyond the thesis: the 3-D counterpart of 2.1-ex1 with its data "
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
    return [ex1] + contact_examples()


def _box_geometry(L, n, boundary):
    from damage_dolfinx.geometries.box import box
    return lambda comm, n_, h: box(comm, (0.0, 0.0, 0.0), (L, L, L), (n_, n_, n_), boundary)


def contact_examples():
    """2.3, 3.1 and 3.3 on boxes, and the wrench plate (3.3-ex3-3d)."""
    from damage_dolfinx.geometries.box import face

    slices = [Figure("fields_slices.png", "", kind="slices")]

    def figs(title):
        return [dataclasses.replace(f, title=title) for f in slices]

    ex23 = _from_2d(
        _thesis_entry("section_2_3", "2.3-ex1"), name="2.3-ex1-3d",
        title="3-D: unit cube clamped at x = 0 on a normal-compliance foundation z = 0, "
              "traction (-10,0,-10) on x = 1",
        n=N_2_3_EX1, diameter=math.sqrt(3),
        mesh=_box_geometry(1.0, N_2_3_EX1, {
            GAMMA_D: face(0, 0.0), GAMMA_C: face(2, 0.0), GAMMA_N: face(0, 1.0)}),
        traction=lambda x, t: ufl.as_vector((-10.0, 0.0, -10.0)),
        assumptions=_3D_COMMON + [
            "geometry: the unit square (x, y) of 2.3-ex1 becomes the cube with its y axis as z: "
            "Gamma_D = {x = 0}, Gamma_C = {z = 0} (foundation below), Gamma_N = {x = 1} with "
            "f_N = (-10, 0, -10); y = 0, y = 1, z = 1 traction-free",
            "memory M_n a DG1 3x3 tensor field (running sum, constant kernel)",
            f"structured n x n x n grid, 6 tetrahedra per hexahedron; run defaults n = "
            f"{N_2_3_EX1}, k = 0.01, T = 1 (the 2-D run's k and T)",
            "solvers: Newton (semismooth in the contact term) with CG on a lagged factorisation "
            "below 3000 unknowns, CG + GAMG (rigid-body modes) above; damage PDE direct / "
            "CG + BoomerAMG likewise (scalable.py)"],
        figures=figs("Example 2.3-1 in 3-D: von Mises stress and damage"))
    ex31_2d = _thesis_entry("section_3_1", "3.1-ex1")
    ex31 = _from_2d(
        ex31_2d.literal or ex31_2d, name="3.1-ex1-3d", default_reading="literal",
        title="3-D: cube (0,6)^3 clamped at x = 0 and x = 6, traction (20t,0,-20t) on top, "
              "normal-compliance foundation below (dynamic)",
        n=N_3_1_EX1, k=K_3_1_EX1, diameter=6 * math.sqrt(3),
        mesh=_box_geometry(6.0, N_3_1_EX1, {
            GAMMA_D: lambda x: face(0, 0.0)(x) | face(0, 6.0)(x), GAMMA_C: face(2, 0.0),
            GAMMA_N: face(2, 6.0)}),
        traction=lambda x, t: ufl.as_vector((20.0 * t, 0.0, -20.0 * t)),
        assumptions=_3D_COMMON + [
            "geometry: the square (0,6)^2 of 3.1-ex1 (G23 layout) becomes the cube (0,6)^3 with "
            "its y axis as z: Gamma_D = {x = 0} and {x = 6}, Gamma_N = {z = 6} with "
            "f_N = (20t, 0, -20t), Gamma_C = {z = 0}; y = 0 and y = 6 traction-free",
            "data: the literal reading (c_nu = 1/mu_nc = 2e4, the stiff foundation: the point of "
            "a contact example; --reading evidence gives the 2-D default reading R1-R2, "
            "c_nu = 5e-5)",
            f"structured n x n x n grid; run defaults n = {N_3_1_EX1}, T = 1, "
            f"k = {K_3_1_EX1:g} (1.8: k_max of stability.py at n = {N_3_1_EX1} in the "
            "assumptions below; k <= 0.8 k_max and dividing T)",
            "solvers: velocity matrix factorised once below VELOCITY_DIRECT_MAX_DOFS_3D "
            "unknowns, CG + GAMG (rigid-body modes, set up once) above; damage obstacle step "
            "SNES vinewtonrsls with CG + Jacobi (as in 2-D)"],
        figures=figs("Example 3.1-1 in 3-D: von Mises stress and damage"))
    ex33 = _from_2d(
        _thesis_entry("section_3_3", "3.3-ex1"), name="3.3-ex1-3d",
        title="3-D: cube (0,6)^3 clamped at x = 0 and x = 6, traction (0,0,-10t) on top, fully "
              "damageable contact with a foundation below (dynamic)",
        n=N_3_3_EX1, diameter=6 * math.sqrt(3),
        params=_thesis_entry("section_3_3", "3.3-ex1").params.replace(stability_check="warn"),
        mesh=_box_geometry(6.0, N_3_3_EX1, {
            GAMMA_D: lambda x: face(0, 0.0)(x) | face(0, 6.0)(x), GAMMA_C: face(2, 0.0),
            GAMMA_N: face(2, 6.0)}),
        traction=lambda x, t: ufl.as_vector((0.0, 0.0, -10.0 * t)),
        assumptions=_3D_COMMON + [
            "geometry: the square (0,6)^2 of 3.3-ex1 becomes the cube (0,6)^3 with its y axis as "
            "z: Gamma_D = {x = 0} and {x = 6}, Gamma_N = {z = 6} with f_N = (0, 0, -10t), "
            "Gamma_C = {z = 0}; y = 0 and y = 6 traction-free",
            f"structured n x n x n grid; run defaults n = {N_3_3_EX1}, k = 0.01, T = 1 (the 2-D "
            "run's k and T); the stability check is on (warn): k_max in summary.json",
            "maximal interpenetration over the Gamma_C vertices with each facet's outward normal "
            "(3-D facets: normal of the triangle) in history.csv and summary.json",
            "solvers: as in 2-D (velocity CG + Jacobi, mass-dominated; damage obstacle step "
            "SNES vinewtonrsls, CG + Jacobi)"],
        figures=figs("Example 3.3-1 in 3-D: von Mises stress and damage"))
    from damage_dolfinx.geometries.wrench_plate import wrench_plate
    ex3_2d = _thesis_entry("section_3_3", "3.3-ex3")
    ex33w = _from_2d(
        ex3_2d, name="3.3-ex3-3d",
        title="3-D: the ring wrench as a plate of thickness 0.4 on a stiff hexagonal screw, "
              "cyclic pressure 1e5 sqrt(2)|sin(pi t)| on the end face of the handle",
        h=H_3_3_EX3, k=K_3_3_EX3, T=T_3_3_EX3, diameter=math.sqrt(11.2 ** 2 + 2.4 ** 2 + 0.4 ** 2),
        mesh=lambda comm, n, h: wrench_plate(comm, h=h, h_contact=h / 2),
        traction=lambda x, t: ufl.as_vector((-1e5 * abs(ufl.sin(math.pi * t)),
                                             -1e5 * abs(ufl.sin(math.pi * t)), 0.0)),
        assumptions=_3D_COMMON + [
            "geometry (geometries/wrench_plate.py): the G35 outline of 3.3-ex3 extruded along z "
            "by the thickness 0.4 (half the handle width, about the proportion of a real "
            "box-end wrench); Gamma_C = the six hexagon faces (the 2-D Gamma_C times the "
            "thickness), Gamma_N = the extruded loaded face with f_N = (-1e5, -1e5, 0)|sin(pi t)| "
            "(a pure pressure), all other faces (outer sides, plate faces z = 0 and z = 0.4) "
            "traction-free; Gamma_D empty (G35/G42: the mass keeps each velocity system "
            "definite)",
            f"gmsh tetrahedra, h = {H_3_3_EX3} (--h), h/2 on the hexagon faces (2-D: h = 0.15, "
            "h/3)",
            f"1.8/G33: k = {K_3_3_EX3:g}, at most 0.8 k_max of stability.py at the default mesh "
            "(k_max in summary.json)",
            f"final time T = {T_3_3_EX3:g} by default (the thesis' T = 6.5 is 650 000 explicit "
            "steps: --T 6.5 runs it; benchmarks/reference_output/contact_3d/examples.md gives the "
            "cost per step)",
            "solvers: as in 2-D (velocity CG + Jacobi with the fast matrix update in serial; "
            "damage obstacle step SNES vinewtonrsls, CG + Jacobi)"],
        figures=figs("Example 3.3-3 in 3-D: von Mises stress and damage in the wrench plate"))
    return [ex23, ex31, ex33, ex33w]
