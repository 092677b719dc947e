"""The catalogue's examples: a thesis example is a :class:`~damage_dolfinx.Problem`
(problem.py) that goes through the same stages (stages.py) and checks as a problem of your own.

A catalogue example (:class:`Example`) is a Problem with
the thesis's metadata: section, readings with their departures, figures, default convergence
study; the run machinery (``runtime/``) takes any Problem as it is, without knowing where it
came from.

Readings (``--reading literal|evidence``): ``literal`` is exactly the stated thesis
data (the catalogue entry itself); ``evidence`` replaces some of it by the values that reproduce
the thesis results with the fewest departures from the text (:class:`Reading`, each departure an
assumption with its thesis lines and the evidence of runs). An example without an evidence
reading has evidence = literal. ``Example.default_reading`` says which one runs by default.
"""
from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Optional

from damage_dolfinx.core.parameters import InputError, TimeGrid
from damage_dolfinx.problem.problem import Figure, Problem  # noqa: F401 (Figure: the catalogue's)
from damage_dolfinx.problem.stages import MAX_STEPS, READINGS  # noqa: F401


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
class Reading:
    """Departures of one reading from the stated data: parameter values, loads, and the
    assumptions (thesis lines, the evidence of runs) that justify them."""
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
    diameter: float = math.nan       # the body's diameter (nan: taken from the mesh)
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
        from damage_dolfinx.core.departures import departures as _departures
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
        from damage_dolfinx.problem.meshes import as_geometry
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
