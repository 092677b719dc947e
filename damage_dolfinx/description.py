"""The run description: what one run is (model, mesh, data, time grid, boundaries, figures),
validated and configured once, then built into a model on the run's ranks.

A :class:`~damage_dolfinx.Problem` resolves to one (:meth:`Problem.example`); a catalogue example
is the same description with the thesis's metadata filled in (section, readings with their
departures, figures, default convergence study). The run machinery (``runtime/``) takes it as
it is, without knowing where it came from.

Readings (``--reading literal|evidence``): ``literal`` is exactly the stated thesis
data (the catalogue entry itself); ``evidence`` replaces some of it by the values that reproduce
the thesis results with the fewest departures from the text (:class:`Reading`, each departure an
assumption with its thesis lines and the measured evidence). An example without an evidence
reading has evidence = literal. ``Example.default_reading`` says which one runs by default.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Optional

from damage_dolfinx.parameters import InputError, ModelParameters, TimeGrid
from damage_dolfinx.models.base import ProblemData


@dataclass
class Figure:
    """A PNG written at the end of a run: fields on the deformed configuration."""
    filename: str
    title: str
    fields: tuple = ("von_mises", "zeta")
    amplification: Optional[float] = None  # None: largest displacement = 10% of diameter
    kind: str = "fields"                   # "fields" (final state), "mesh" (setting and mesh),
    #                                        "history" (fields = ((column, label), ...) of history.csv)
    #                                        or "profiles" (summary "profiles" + zeta_probe, 3.3-ex2)
    #                                        or "slices" (3-D: sections through the body, slices.py)
    times: tuple = ()                      # draw "fields" at these times (file name gets _t<t>)
    mesh_lines: bool = False               # draw the deformed mesh edges ("deformed mesh" figures)


#: more time steps than this need the parameter allow_long (--allow-long)
MAX_STEPS = 10_000_000

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
    """One run description (a catalogue example, or a Problem resolved)."""
    id: str
    title: str
    section: str
    params: ModelParameters
    T: float
    k: float
    make_geometry: Callable          # (comm, n, h) -> Geometry
    model: object                    # the model: an id ("2.1" ... "3.3") or a Model class
    diameter: float
    n: Optional[int] = None          # structured meshes: cells per side
    h: Optional[float] = None        # gmsh meshes: element size
    dim: int = 2                     # space dimension of the mesh (3: the 3-D examples)
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
    damage_law: Optional[object] = None           # laws.DamageLaw (None: the thesis law)
    irreversible: bool = False                    # zeta_n <= zeta_{n-1}
    boundaries: Optional[dict] = None             # role -> tags (None: tags 1, 2, 3 as they are)
    own: bool = False                             # an own problem (Problem), not the catalogue
    allow_unstable: bool = False                  # a k above k_max: a warning, not a refusal
    _requirements: Optional[tuple] = field(default=None, repr=False, compare=False)

    @property
    def model_id(self) -> str:
        """The id of the example's model (its ``model`` may be the class itself)."""
        return self.model if isinstance(self.model, str) else self.model.id

    def with_reading(self, name=None) -> "Example":
        """This example under reading ``name`` (None: the default); raises InputError."""
        name = name or self.default_reading
        if name not in READINGS:
            raise InputError(f"unknown reading {name!r}; known: {', '.join(READINGS)}")
        base = self.literal or self
        r = base.readings.get(name, Reading()) if name != "literal" else Reading()
        label = "the default" if name == base.default_reading else "not the default"
        from damage_dolfinx.departures import departures as _departures
        count = len(_departures(base.assumptions + r.assumptions))
        departures = (f"{count} departure(s) from the stated data, listed as R-entries and "
                      f"departure entries" if count else "no departure from the stated data")
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
        overrides = dict(overrides or {})
        allow_long = bool(overrides.pop("allow_long", False))
        from damage_dolfinx.models.registry import model as model_info
        info = model_info(self.model)
        # a time step you choose above k_max is refused (stability_check = error) unless the
        # check is set explicitly (--allow-unstable sets warn); the thesis's own steps (defaults,
        # convergence tables) run as the thesis ran them, with a warning above k_max
        action = overrides.pop("stability_check", None) \
            if "stability_check" not in self.params.extra else overrides.get("stability_check")
        if action is None:
            action = "error" if (k is not None or self.own) and not self.allow_unstable \
                else "warn"
            if "stability_check" in self.params.extra and k is not None:
                overrides["stability_check"] = action
        from damage_dolfinx.models.registry import validate
        params = validate(info, self.params.replace(**overrides))
        T = self.T if T is None else float(T)
        if k is None and self.own:  # an own problem's k is its author's choice
            k = self.k
        k = self.default_k(n, h, T, params) if k is None else float(k)
        time = TimeGrid(k, T)
        k_max = info.k_max(params)
        if k > k_max:
            from damage_dolfinx.numerics.stability import check_time_step
            check_time_step(k, k_max, f"{self.id}: {info.stability_limit}", action=action)
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
            from damage_dolfinx.validation import mesh_path_problem
            raise InputError(f"mesh file {str(mesh_file)!r} "
                             f"{mesh_path_problem(Path(mesh_file)) or 'is not a file'}")
        if time.num_steps > MAX_STEPS and not allow_long:
            raise InputError(f"{time.num_steps} time steps (T = {T:g}, k = {k:g}) is more than "
                             f"{MAX_STEPS:.0e}; choose a larger k, or allow_long=True")
        if mesh_file is not None and self.dim != 2:
            raise InputError(f"--mesh reads 2-D gmsh meshes; example {self.id} is {self.dim}-D")
        if mesh_file is None and not self.own:
            from mpi4py import MPI
            from damage_dolfinx.runtime.resources import check_memory
            # a mesh that cannot fit is refused now (collective on the run's ranks: a serial
            # cell of a convergence study is built on one rank alone)
            check_memory(self, n, h, comm or MPI.COMM_WORLD)
        return params, time, n, h, mesh_file

    def mesh_requirements(self):
        """(dimension, facet tags) a --mesh file must have: those of the built-in geometry
        (built serially at the default size, once per example; runfolder.check_mesh_file and
        required_tags both ask)."""
        if self._requirements is None:
            import numpy as np
            from mpi4py import MPI
            geometry = self.make_geometry(MPI.COMM_SELF, self.n, self.h)
            self._requirements = (self.dim, tuple(int(t) for t in
                                                  np.unique(geometry.facet_tags.values)))
        return self._requirements

    def build(self, comm, n=None, k=None, T=None, h=None, overrides=None, mesh_file=None,
              configured=None):
        """Mesh, data and model of one run; ``configured``: what :meth:`configure` returned
        for the same arguments (None: configured here)."""
        data = self.problem_data(comm, n, k, T, h, overrides, mesh_file, configured)
        from damage_dolfinx.models.registry import model as model_info
        return model_info(self._resolved(overrides)[0].model)(data)

    def problem_data(self, comm, n=None, k=None, T=None, h=None, overrides=None,
                     mesh_file=None, configured=None):
        """Mesh and data of one run, checked against the mesh (no solver is set up)."""
        ex, overrides = self._resolved(overrides)
        if ex is not self:
            return ex.problem_data(comm, n, k, T, h, overrides, mesh_file, configured)
        params, time, n, h, mesh_file = configured or \
            self.configure(n, k, T, h, overrides, mesh_file, comm)
        from damage_dolfinx.meshes import read_mesh, retag
        if mesh_file is not None:
            geometry = read_mesh(mesh_file, comm, self.dim)
            required = self.required_tags(comm)
        else:
            geometry = self.make_geometry(comm, n, h)
            required = None
        from damage_dolfinx.models.registry import model as model_info
        geometry = retag(geometry, self.boundaries, required, model_info(self.model))
        data = ProblemData(self.id, geometry, params, time, self.body_force, self.traction,
                           self.zeta0, self.builders, self.damage_law, self.irreversible)
        from damage_dolfinx.validation import check_data
        check_data(data)  # loads, law, zeta0 against the mesh (validation.py)
        return data

    def default_k(self, n, h, T, params) -> float:
        """The default time step at mesh (n, h) and final time T: the example's k, made smaller
        in proportion to the cell size on meshes finer than the default for the dynamic models
        (their k_max is proportional to h), kept below 0.8 k_max for the quasistatic ones with an
        explicit term, and made to divide T (k = T/N, N the smallest count with k below that)."""
        from damage_dolfinx.models.registry import model as model_info
        info = model_info(self.model)
        k, scaled = self.k, False
        if info.dynamic:  # k_max proportional to h
            if n is not None and self.n and n > self.n:
                k, scaled = k * self.n / n, True
            if h is not None and self.h and h < self.h:
                k, scaled = k * h / self.h, True
        k_max = info.k_max(params)
        if k > 0.8 * k_max:
            k, scaled = 0.8 * k_max, True
        ratio = T / k
        if not scaled and abs(ratio - round(ratio)) <= 1e-8 * max(1.0, ratio):
            return self.k  # the example's own k, bit for bit
        return T / math.ceil(ratio * (1 - 1e-12))

    def required_tags(self, comm) -> dict:
        """role -> tag of every boundary part the example's own mesh has (a mesh file given for
        the example must have them too; the tags of mesh_requirements, found on rank 0)."""
        from damage_dolfinx.models.registry import CLAMPED, TRACTION, CONTACT
        tags = comm.bcast(self.mesh_requirements()[1] if comm.rank == 0 else None, root=0)
        names = {CLAMPED: "clamped (Gamma_D)", TRACTION: "traction (Gamma_N)",
                 CONTACT: "contact (Gamma_C)"}
        return {names[t]: t for t in (CLAMPED, TRACTION, CONTACT) if t in tags}
