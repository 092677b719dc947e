"""The run description's stages and the catalogue's examples.

A run is a :class:`~damage_dolfinx.Problem` (problem.py). :func:`configure` decides the values
of one run (validated data, time grid, mesh level and file) and :func:`build` builds its mesh on
the run's ranks and the model from it. A catalogue example (:class:`Example`) is a Problem with
the thesis's metadata: section, readings with their departures, figures, default convergence
study; the run machinery (``runtime/``) takes any Problem as it is, without knowing where it
came from.

Readings (``--reading literal|evidence``): ``literal`` is exactly the stated thesis
data (the catalogue entry itself); ``evidence`` replaces some of it by the values that reproduce
the thesis results with the fewest departures from the text (:class:`Reading`, each departure an
assumption with its thesis lines and the measured evidence). An example without an evidence
reading has evidence = literal. ``Example.default_reading`` says which one runs by default.
"""
from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Optional

from damage_dolfinx.parameters import InputError, TimeGrid
from damage_dolfinx.problem import MAX_STEPS, READINGS, Problem  # noqa: F401


#: the catalogue's short labels of its assumptions (a "G" and a number, with a slash-joined
#: list-item number before it, a colon after it, or in brackets), and what each says in words:
#: a value the thesis does not give, assumed
_LABELS = [
    (re.compile(r"^(?:[\d.]+/)?G\d+[a-z]?(?:/G?\d+[a-z]?)*(?:/[\d.]+)?:\s*"), "assumed: "),
    (re.compile(r"\((?:G\d+[a-z]?)(?:[,/ ]+G\d+[a-z]?)*\)"), "(assumed)"),
    (re.compile(r"\b(?:[\d.]+/)?G\d+[a-z]?(?:/G\d+[a-z]?)*\b"), "assumed"),
]


def in_words(assumption: str) -> str:
    """An assumption of the catalogue as a run records it (summary.json): its short labels
    replaced by what they mean (a labelled ``kappa = 1 ...`` -> ``assumed: kappa = 1 ...``).
    The reading entries (``R<n> (evidence reading; <basis>): ...``) keep their form: it says
    what they are, and the departure records are read from it."""
    for pattern, words in _LABELS:
        assumption = pattern.sub(words, assumption)
    return assumption


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


@dataclass
class Reading:
    """Departures of one reading from the stated data: parameter values, loads, and the
    assumptions (thesis lines, measured evidence) that justify them."""
    overrides: dict = field(default_factory=dict)
    traction: Optional[Callable] = None
    body_force: Optional[Callable] = None
    assumptions: list = field(default_factory=list)


@dataclass
class Example(Problem):
    """A thesis example: a :class:`~damage_dolfinx.Problem` (``name`` its id, ``mesh`` a
    family ``(comm, n, h) -> Geometry``, ``params`` the full data) with the thesis's metadata.
    Its default k follows the mesh (:meth:`default_k`) and its own k runs as the thesis ran it
    (a warning above k_max); a k you choose above k_max is refused."""
    title: str = ""
    section: str = ""
    diameter: float = math.nan       # the body's diameter (nan: measured on the mesh)
    h: Optional[float] = None        # gmsh meshes: element size
    dim: int = 2                     # space dimension of the mesh (3: the 3-D examples)
    assumptions: list = field(default_factory=list)
    figures: list = field(default_factory=list)
    convergence: Optional[dict] = None  # default study {ref_n, ref_k, n: [...], k: [...]}
    readings: dict = field(default_factory=dict)  # {"evidence": Reading} (literal = the data)
    default_reading: str = "literal"
    reading: Optional[str] = None                 # the reading applied (None: the raw entry)
    literal: Optional["Example"] = field(default=None, repr=False, compare=False)
    mesh_file: Optional[str] = None               # a gmsh file replacing the mesh (--mesh)
    _requirements: Optional[tuple] = field(default=None, repr=False, compare=False)

    own = False

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
            assumptions=[f"reading: {name} ({label}; {departures})"]
            + [in_words(a) for a in base.assumptions + r.assumptions], reading=name,
            literal=base)

    def checked(self) -> "Example":
        """The example under its reading (the default one when none is applied yet)."""
        return self if self.reading is not None else self.with_reading(None)

    def _resolved(self, overrides):
        """(example under the reading named in ``overrides``, overrides without it)."""
        overrides = dict(overrides or {})
        name = overrides.pop("reading", None)
        if self.reading is None or (name is not None and name != self.reading):
            return self.with_reading(name), overrides
        return self, overrides

    def make_geometry(self, comm, n=None, h=None):
        """The example's own mesh at size n (structured) or h (gmsh) on ``comm``."""
        from damage_dolfinx.meshes import as_geometry
        return as_geometry(self.mesh(comm, n, h) if self.family else self.mesh, comm)

    def mesh_requirements(self):
        """(dimension, facet tags) a --mesh file must have: those of the built-in geometry
        (built serially at the default size, once per example; runfolder.check_mesh_file and
        required_tags both ask)."""
        base = self.literal or self  # the entry as written (default size), shared by readings
        if base._requirements is None:
            import numpy as np
            from mpi4py import MPI
            geometry = base.make_geometry(MPI.COMM_SELF, base.n, base.h)
            base._requirements = (base.dim, tuple(int(t) for t in
                                                  np.unique(geometry.facet_tags.values)))
        return base._requirements

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


def configure(ex: Problem, n=None, k=None, T=None, h=None, overrides=None, mesh_file=None,
              comm=None) -> Problem:
    """``ex`` (under its reading) as one run has it: validated data, T, k, the mesh level and
    file; InputError otherwise (see :meth:`Problem.configure`)."""
    overrides = dict(overrides or {})
    allow_long = bool(overrides.pop("allow_long", False))
    from damage_dolfinx.models.registry import model as model_info, validate
    info = model_info(ex.model)
    # a time step you choose above k_max is refused (stability_check = error) unless the
    # check is set explicitly (--allow-unstable sets warn); the thesis's own steps (defaults,
    # convergence tables) run as the thesis ran them, with a warning above k_max
    action = overrides.pop("stability_check", None) \
        if "stability_check" not in ex.params.extra else overrides.get("stability_check")
    if action is None:
        action = "error" if (k is not None or ex.own) and not ex.allow_unstable \
            else "warn"
        if "stability_check" in ex.params.extra and k is not None:
            overrides["stability_check"] = action
    # validated once: a checked problem's data again only when a run changes them
    params = ex.params if ex._checked and not overrides else \
        validate(info, ex.params.replace(**overrides))
    T = ex.T if T is None else float(T)
    k = ex.default_k(n, h, T, params) if k is None else float(k)
    time = TimeGrid(k, T)
    k_max = info.k_max(params)
    if k > k_max:
        from damage_dolfinx.numerics.stability import check_time_step
        check_time_step(k, k_max, f"{ex.id}: {info.stability_limit}", action=action)
    if n is not None and ex.n is None:
        raise InputError(f"example {ex.id} uses a gmsh mesh: set its size with --h, not --n")
    if h is not None and ex.h is None:
        raise InputError(f"example {ex.id} uses a structured mesh: set it with --n, not --h")
    n = ex.n if n is None else int(n)
    h = ex.h if h is None else float(h)
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
    if mesh_file is not None and ex.dim != 2:
        raise InputError(f"--mesh reads 2-D gmsh meshes; example {ex.id} is {ex.dim}-D")
    if mesh_file is None and not ex.own:
        from mpi4py import MPI
        from damage_dolfinx.runtime.resources import check_memory
        # a mesh that cannot fit is refused now (collective on the run's ranks: a serial
        # cell of a convergence study is built on one rank alone)
        check_memory(ex, n, h, comm or MPI.COMM_WORLD)
    sized = dict(n=n, h=h, mesh_file=str(mesh_file) if mesh_file is not None else None) \
        if not ex.own else dict(n=n)
    return dataclasses.replace(ex, params=params, T=T, k=k, _checked=True, **sized)


def on_mesh(c: Problem, comm) -> Problem:
    """The configured problem ``c`` on its mesh on ``comm`` (the problem's own, or the mesh file
    replacing it, with the example's tags required), the boundary roles named, checked against
    the loads, law and initial damage: what a model is built from (no solver set up)."""
    from damage_dolfinx.meshes import read_mesh, retag
    from damage_dolfinx.models.registry import model
    from damage_dolfinx.validation import check_data
    if c.mesh_file is not None:
        geometry = read_mesh(c.mesh_file, comm, c.dim)
        required = c.required_tags(comm)
    else:
        geometry = c.make_geometry(comm, c.n, c.h)
        required = None
    built = dataclasses.replace(c, mesh=retag(geometry, c.boundaries, required, model(c.model)))
    check_data(built)  # loads, law, zeta0 against the mesh (validation.py)
    return built


def build(c: Problem, comm):
    """The model of the configured problem ``c`` on ``comm``, built on :func:`on_mesh`."""
    from damage_dolfinx.models.registry import model
    return model(c.model)(on_mesh(c, comm))
