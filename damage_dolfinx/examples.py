"""Catalogue of the thesis examples by id (``2.1-ex1`` ...): data, geometry, scheme, defaults.

Every value the thesis leaves open is an explicit assumption, listed with its PROBLEMS.md gap
number in the example's ``assumptions`` and copied into each run's summary.json.

Readings (``--reading literal|evidence``, issue 16): ``literal`` is exactly the stated thesis
data (the catalogue entry itself); ``evidence`` replaces some of it by the values that reproduce
the thesis results with the fewest departures from the text (:class:`Reading`, each departure an
assumption R<n> with its thesis lines and the measured evidence). An example without an evidence
reading has evidence = literal. ``Example.default_reading`` says which one runs by default.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Optional

from .parameters import InputError, ModelParameters, TimeGrid
from .problems.base import ProblemData


@dataclass
class Figure:
    """A PNG written at the end of a run: fields on the deformed configuration."""
    filename: str
    title: str
    fields: tuple = ("von_mises", "zeta")
    amplification: Optional[float] = None  # None: largest displacement = 10% of diameter (G40)
    kind: str = "fields"                   # "fields" (final state), "mesh" (setting and mesh),
    #                                        "history" (fields = ((column, label), ...) of history.csv)
    #                                        or "profiles" (summary "profiles" + zeta_probe, 3.3-ex2)
    #                                        or "slices" (3-D: sections through the body, slices.py)
    times: tuple = ()                      # draw "fields" at these times (file name gets _t<t>)
    mesh_lines: bool = False               # draw the deformed mesh edges ("deformed mesh" figures)


#: the readings of the thesis data (``--reading``)
READINGS = ("literal", "evidence")


@dataclass
class Reading:
    """Departures of one reading from the stated data: parameter values, loads, and the
    assumptions (thesis lines, measured evidence) that justify them."""
    overrides: dict = field(default_factory=dict)
    traction: Optional[Callable] = None
    body_force: Optional[Callable] = None
    assumptions: list = field(default_factory=list)


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
    dim: int = 2                     # space dimension of the mesh (3: the issue-17 examples)
    body_force: Optional[Callable] = None
    traction: Optional[Callable] = None
    zeta0: object = 1.0
    assumptions: list = field(default_factory=list)
    figures: list = field(default_factory=list)
    convergence: Optional[dict] = None  # default study {ref_n, ref_k, n: [...], k: [...]}
    builders: dict = field(default_factory=dict)  # problem-specific builders (ProblemData)
    readings: dict = field(default_factory=dict)  # {"evidence": Reading} (literal = the data)
    default_reading: str = "literal"
    reading: Optional[str] = None                 # the reading applied (None: the raw entry)
    literal: Optional["Example"] = field(default=None, repr=False, compare=False)

    def with_reading(self, name=None) -> "Example":
        """This example under reading ``name`` (None: the default); raises InputError."""
        name = name or self.default_reading
        if name not in READINGS:
            raise InputError(f"unknown reading {name!r}; known: {', '.join(READINGS)}")
        base = self.literal or self
        r = base.readings.get(name, Reading()) if name != "literal" else Reading()
        label = "the default" if name == base.default_reading else "not the default"
        departures = (f"{len(r.assumptions)} departure(s) from the stated data, listed as R-entries"
                      if r.assumptions else "no departure from the stated data")
        return dataclasses.replace(
            base, params=base.params.replace(**r.overrides),
            traction=r.traction or base.traction, body_force=r.body_force or base.body_force,
            assumptions=[f"reading: {name} ({label}; {departures})"] + base.assumptions
            + r.assumptions, reading=name, literal=base)

    def _resolved(self, overrides):
        """(example under the reading named in ``overrides``, overrides without it)."""
        overrides = dict(overrides or {})
        name = overrides.pop("reading", None)
        if self.reading is None or (name is not None and name != self.reading):
            return self.with_reading(name), overrides
        return self, overrides

    def configure(self, n=None, k=None, T=None, h=None, overrides=None, mesh_file=None,
                  comm=None):
        """Validated (params, time grid, n, h, mesh_file) for a run; raises InputError.
        ``overrides`` may name the reading (key ``reading``). ``comm``: the ranks of the run
        (default all), which the memory check is collective on."""
        ex, overrides = self._resolved(overrides)
        if ex is not self:
            return ex.configure(n, k, T, h, overrides, mesh_file, comm)
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
        if mesh_file is None:
            from mpi4py import MPI
            from .resources import check_memory
            # a mesh that cannot fit is refused now (collective on the run's ranks: a serial
            # cell of a convergence study is built on one rank alone)
            check_memory(self, n, h, comm or MPI.COMM_WORLD)
        return params, time, n, h, mesh_file

    def build(self, comm, n=None, k=None, T=None, h=None, overrides=None, mesh_file=None):
        """Mesh, data and time stepper of one run (after validation)."""
        ex, overrides = self._resolved(overrides)
        if ex is not self:
            return ex.build(comm, n, k, T, h, overrides, mesh_file)
        params, time, n, h, mesh_file = self.configure(n, k, T, h, overrides, mesh_file, comm)
        if mesh_file is not None:
            from .geometries import read_msh
            geometry = read_msh(comm, mesh_file)
        else:
            geometry = self.make_geometry(comm, n, h)
        data = ProblemData(self.id, geometry, params, time, self.body_force, self.traction,
                           self.zeta0, self.builders)
        return self.make_stepper(data)


#: catalogue modules (damage_dolfinx/catalogue/<name>.py), each with examples() -> [Example]
SECTIONS = ["section_2_1", "section_2_2", "section_2_3", "bridge", "section_2_4", "section_3_1",
            "section_3_2", "section_3_3", "section_3d", "section_3d_tresca"]


def catalogue(reading=None) -> dict:
    """All examples by id, in section order, under ``reading`` (None: each one's default)."""
    import importlib
    out = {}
    for name in SECTIONS:
        module = importlib.import_module(f"{__package__}.catalogue.{name}")
        out.update({ex.id: ex.with_reading(reading) for ex in module.examples()})
    return out


def get(example_id: str, reading=None) -> Example:
    """The example under ``reading`` (None: its default reading)."""
    if reading is not None and reading not in READINGS:
        raise InputError(f"unknown reading {reading!r}; known: {', '.join(READINGS)}")
    examples = catalogue(reading)
    if example_id not in examples:
        raise InputError(f"unknown example id {example_id!r}; known ids: {', '.join(examples)} "
                         f"(see `damage-dolfinx list`)")
    return examples[example_id]
