"""3-D examples with Tresca friction: the
Kelvin-Voigt examples of Sections 2.2 and 3.2 on a box, bilateral contact and Tresca friction on
its bottom face with a 2-D tangent plane (friction/: Phi_eps(v_tau) = g v_tau / max(|v_tau|, eps)
with v_tau a vector, two tangents per node).

The data of each 2-D example are kept; the unit square (x, y) is extruded along z to the unit
cube, so that the contact side y = 0 becomes the face y = 0 (tangents x and z), the clamped and
loaded sides the faces x = 0 and x = 1, and the faces z = 0, z = 1 are traction-free (their
Poisson contraction gives the contact face a tangential velocity along z too).
"""
import dataclasses
import math

import ufl

from damage_dolfinx.catalogue.examples import Figure
from damage_dolfinx.geometries import GAMMA_C, GAMMA_D, GAMMA_N

#: default cells per side (n x n x n hexahedra, 6 tetrahedra each)
N_2_2_EX1, N_3_2_EX1 = 8, 8

_COMMON = [
    "3-D isotropic elasticity lambda tr(eps) I + 2 mu eps (its plane-stress reduction is B of "
    "(2.36)) in A = B/m_visc and the elastic force; Phi_L componentwise on the 3x3 tensor",
    "bilateral contact v.nu = 0 and Tresca friction on the face y = 0 with a 2-D tangent plane: "
    "j(w) = sum_i m_i g |w_tau,i| (vertex rule on the triangles), the regularised law "
    "Phi_eps(v_tau) = g v_tau / max(|v_tau|, eps) (2.99 with |.| the Euclidean norm; in 2-D it "
    "is g max(-1, min(1, v_tau/eps))), two tangents per node (the coordinate axes x and z); "
    "the four friction solvers as in 2-D (--set friction_solver=...)",
    "1.9/G37 in 3-D: von Mises sqrt(3/2 dev(sigma):dev(sigma)), cell-wise (DG0)",
    "figures: sections through the body (slices.py); XDMF of the fields for ParaView",
    "solvers: friction Newton with the 2x2-block Jacobian assembled algebraically, CG "
    "preconditioned by the Cholesky factorisation of an earlier Jacobian (PETSc serial, MUMPS "
    "parallel; -friction_ options override); the active-set attempt likewise with GMRES and LU; "
    "damage obstacle step SNES vinewtonrsls as in 2-D",
]


def _unit_cube(comm, n, h):
    from damage_dolfinx.geometries.box import box, face
    return box(comm, (0.0, 0.0, 0.0), (1.0, 1.0, 1.0), (n, n, n), {
        GAMMA_C: face(1, 0.0), GAMMA_D: face(0, 0.0), GAMMA_N: face(0, 1.0)})


def _cube_gamma_n_left(comm, n, h):
    """3.2-ex1's layout: Gamma_D = {x = 1}, f_N on {x = 0}, Gamma_C = {y = 0}."""
    from damage_dolfinx.geometries.box import box, face
    return box(comm, (0.0, 0.0, 0.0), (1.0, 1.0, 1.0), (n, n, n), {
        GAMMA_C: face(1, 0.0), GAMMA_D: face(0, 1.0), GAMMA_N: face(0, 0.0)})


def _from_2d(ex2d, reading_traction=None, **changes):
    """A 3-D entry with the data of ``ex2d`` (the literal entry: its parameters, time grid and
    readings; a reading's 2-D traction replaced by ``reading_traction``), no convergence
    study."""
    assumptions = ([f"beyond the thesis: the 3-D counterpart of {ex2d.id} with its "
                    "data; its 2-D assumptions follow (marked '2-D:'), the geometry, mesh and "
                    "solver lines among them superseded by the 3-D lines after them"]
                   + [f"2-D: {a}" for a in ex2d.assumptions] + _COMMON
                   + changes.pop("assumptions"))
    readings = {name: (dataclasses.replace(r, traction=reading_traction) if r.traction else r)
                for name, r in ex2d.readings.items()}
    return dataclasses.replace(ex2d, dim=3, convergence=None, literal=None, reading=None,
                               readings=readings, assumptions=assumptions, **changes)


def _entry(module, example_id):
    """The raw (literal) 2-D catalogue entry."""
    import importlib
    m = importlib.import_module(f"{__package__}.{module}")
    return next(ex for ex in m.examples() if ex.id == example_id)


def examples():
    e22 = _from_2d(
        _entry("section_2_2", "2.2-ex1"),
        lambda x, t: ufl.as_vector((100.0 * (ufl.exp(t) - 1.0), 0.0, 0.0)),
        name="2.2-ex1-3d",
        title="3-D: unit cube clamped at x = 0, traction (100,0,0)e^t on x = 1, Tresca g = 5 "
              "on y = 0",
        n=N_2_2_EX1, diameter=math.sqrt(3), mesh=_unit_cube,
        traction=lambda x, t: ufl.as_vector((100.0 * ufl.exp(t), 0.0, 0.0)),
        assumptions=[
            "geometry: Gamma_D = {x = 0}, Gamma_N = {x = 1}, Gamma_C = {y = 0}; y = 1, z = 0, "
            "z = 1 traction-free; the evidence reading (the default, as in 2-D) loads with "
            "(100, 0, 0)(e^t - 1)",
            f"structured n x n x n grid, 6 tetrahedra per hexahedron; run defaults n = "
            f"{N_2_2_EX1}, k = 0.01, T = 1 (the 2-D run's k and T)"],
        figures=[Figure("fields_slices.png", "Example 2.2-1 in 3-D: von Mises stress and damage",
                        kind="slices")])
    e32 = _from_2d(
        _entry("section_3_2", "3.2-ex1"), name="3.2-ex1-3d",
        title="3-D: unit cube clamped at x = 1, traction (200,0,0)(e^t - 1) on x = 0, Tresca "
              "g = 5 on y = 0 (dynamic)",
        n=N_3_2_EX1, diameter=math.sqrt(3), mesh=_cube_gamma_n_left,
        traction=lambda x, t: ufl.as_vector((200.0 * (ufl.exp(t) - 1.0), 0.0, 0.0)),
        assumptions=[
            "geometry: Gamma_D = {x = 1}, Gamma_N = {x = 0}, Gamma_C = {y = 0}; y = 1, z = 0, "
            "z = 1 traction-free",
            f"structured n x n x n grid; run defaults n = {N_3_2_EX1}, k = 0.01, T = 1 (the 2-D "
            "run's k and T; the stability check in summary.json)"],
        figures=[Figure("fields_slices.png", "Example 3.2-1 in 3-D: von Mises stress and damage",
                        kind="slices")])
    return [e22, e32]
