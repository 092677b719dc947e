"""Catalogue of the thesis examples by id (``2.1-ex1`` ...): data, geometry, scheme, defaults.

Every value the thesis leaves open is an explicit assumption, listed with its PROBLEMS.md gap
number in the example's ``assumptions`` and copied into each run's summary.json.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Optional

import ufl

from .parameters import InputError, ModelParameters, TimeGrid
from .problems.base import ProblemData


@dataclass
class Figure:
    """A PNG written at the end of a run: fields on the deformed configuration."""
    filename: str
    title: str
    fields: tuple = ("von_mises", "zeta")
    amplification: Optional[float] = None  # None: largest displacement = 10% of diameter (G40)
    kind: str = "fields"                   # "fields" (final state) or "mesh" (setting and mesh)


@dataclass
class Example:
    id: str
    title: str
    section: str
    params: ModelParameters
    T: float
    k: float
    make_geometry: Callable          # (comm, n, h) -> Geometry
    make_stepper: Callable           # ProblemData -> TimeStepper
    diameter: float
    n: Optional[int] = None          # structured meshes: cells per side
    h: Optional[float] = None        # gmsh meshes: element size
    body_force: Optional[Callable] = None
    traction: Optional[Callable] = None
    zeta0: object = 1.0
    assumptions: list = field(default_factory=list)
    figures: list = field(default_factory=list)
    convergence: Optional[dict] = None  # default study {ref_n, ref_k, n: [...], k: [...]}

    def configure(self, n=None, k=None, T=None, h=None, overrides=None, mesh_file=None):
        """Validated (params, time grid, n, h, mesh_file) for a run; raises InputError."""
        params = self.params.replace(**(overrides or {})).validate()
        time = TimeGrid(self.k if k is None else float(k), self.T if T is None else float(T))
        if n is not None and self.n is None:
            raise InputError(f"example {self.id} uses a gmsh mesh: set its size with --h, not --n")
        if h is not None and self.h is None:
            raise InputError(f"example {self.id} uses a structured mesh: set it with --n, not --h")
        n = self.n if n is None else int(n)
        h = self.h if h is None else float(h)
        if n is not None and n < 1:
            raise InputError(f"number of cells per side n must be >= 1, got n = {n}")
        if h is not None and not h > 0:
            raise InputError(f"mesh size h must be positive, got h = {h}")
        if mesh_file is not None and not Path(mesh_file).is_file():
            raise InputError(f"mesh file {str(mesh_file)!r} does not exist")
        return params, time, n, h, mesh_file

    def build(self, comm, n=None, k=None, T=None, h=None, overrides=None, mesh_file=None):
        """Mesh, data and time stepper of one run (after validation)."""
        params, time, n, h, mesh_file = self.configure(n, k, T, h, overrides, mesh_file)
        if mesh_file is not None:
            from .geometries import read_msh
            geometry = read_msh(comm, mesh_file)
        else:
            geometry = self.make_geometry(comm, n, h)
        data = ProblemData(self.id, geometry, params, time, self.body_force, self.traction,
                           self.zeta0)
        return self.make_stepper(data)


# ------------------------------------------------------------------------- Section 2.1
def _section_2_1():
    from .geometries.disc_minus_diamond import disc_minus_diamond
    from .geometries.square_with_hole import square_with_hole
    from .problems.elastic_2_1 import ElasticDamage

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
        id="2.1-ex1", section="2.1",
        title="square (0,5)^2 with clamped hole [2,3]^2, body force (50,25)t: convergence example",
        params=ModelParameters(**common, lam_u_plus=1000.0, lam_u_minus=100.0),
        T=1.0, k=0.01, n=20, diameter=5 * math.sqrt(2),
        make_geometry=lambda comm, n, h: square_with_hole(comm, n),
        make_stepper=ElasticDamage,
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
            id=f"2.1-ex2{letter}", section="2.1",
            title=f"disc |x|<4 minus diamond, clockwise traction (5y,-5x)t: {kind} damage only",
            params=ModelParameters(**common, lam_u_plus=lam_plus, lam_u_minus=lam_minus),
            T=1.0, k=0.01, h=0.1, diameter=8.0,
            make_geometry=lambda comm, n, h: disc_minus_diamond(comm, h=h, h_corner=h / 2),
            make_stepper=ElasticDamage,
            traction=lambda x, t: ufl.as_vector((5.0 * x[1] * t, -5.0 * x[0] * t)),
            assumptions=common_assumptions + [
                "G2: Gamma_D = inner diamond |x1|+|x2| = 1 (clamped), Gamma_N = circle",
                "G2: gmsh h = 0.1 (h/2 = 0.05 near the diamond corners), k = 0.01",
                "G1 (revised) applied to Example 2 as well: kappa = 1 (PROBLEMS.md's example line "
                "still says 1e-2; G1 supersedes it; override with --set kappa=0.01)"],
            figures=[Figure("figure_2_3.png", "Example 2.1-2: setting and mesh", kind="mesh"),
                     Figure(figure, f"Example 2.1-2 ({kind} damage only): von Mises stress and "
                            "damage")])

    return [ex1,
            ex2("a", 1000.0, 0.0, "figure_2_4.png", "tension"),
            ex2("b", 0.0, 1000.0, "figure_2_5.png", "compression")]


def catalogue() -> dict:
    """All examples by id."""
    return {ex.id: ex for ex in _section_2_1()}


def get(example_id: str) -> Example:
    examples = catalogue()
    if example_id not in examples:
        raise InputError(f"unknown example id {example_id!r}; known ids: {', '.join(examples)} "
                         f"(see `damage-dolfinx list`)")
    return examples[example_id]
