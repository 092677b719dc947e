"""A run: one of the models on a mesh, with its boundary parts, loads, data and damage law
(:class:`Problem`). Your own problems are Problems; a thesis example of the catalogue is a
Problem with its thesis metadata (:class:`damage_dolfinx.problem.example.Example`). Run it with :func:`damage_dolfinx.run` (summary.json, XDMF, history.csv, checkpoints
and restart, signals, figures, MPI) or study its convergence with :func:`damage_dolfinx.converge`.

Example: the Kelvin-Voigt model with Tresca friction (``"2.2"``) on a rectangle clamped on the
left, pulled on the right, with friction at the bottom::

    import ufl
    from mpi4py import MPI
    import damage_dolfinx as dd
    from damage_dolfinx.geometries.rectangle import rectangle, side

    def mesh(comm, n):           # tags: 1 left, 2 right, 3 bottom
        return rectangle(comm, (0, 0), (2, 0.5), 4 * n, n,
                         {1: side(0, 0.0), 2: side(0, 2.0), 3: side(1, 0.0)})

    problem = dd.Problem(
        model="2.2", mesh=mesh, n=8, T=1.0,
        boundaries={"clamped": 1, "traction": 2, "tresca": 3},
        traction=lambda x, t: ufl.as_vector((50.0 * t, 0.0)),
        params={"E": 2000.0, "g_fric": 10.0})
    summary = dd.run(problem, "results/my-rectangle")
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from functools import cached_property
from typing import Callable, Optional, Union

from damage_dolfinx.core.parameters import InputError, ModelParameters, TimeGrid

from damage_dolfinx.problem import stages
from damage_dolfinx.problem.stages import MAX_STEPS, READINGS  # noqa: F401


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
class Problem:
    """One run: a model on a mesh, with its data, loads and time grid.

    The same object goes through the three stages of a run: as you write it (a mesh family,
    changes to the model's defaults, k perhaps None), :meth:`checked` (every argument
    validated, once), :meth:`configure` (the values of one run: validated data, k, T, mesh
    level) and :meth:`build` on the run's ranks, which gives the model the problem with its mesh
    built (``mesh`` a :class:`~damage_dolfinx.geometries.Geometry`): that is what a
    :class:`~damage_dolfinx.Model` is built from, and what it reads as ``self.data``
    (``geometry``, ``params``, ``time``, the loads, ``zeta0``, ``builders``, ...).

    Attributes:
        model: a model id, a key of :data:`damage_dolfinx.MODELS` (which lists them with
            their titles), or a :class:`~damage_dolfinx.Model` class, e.g. one of your own.
        mesh: a :class:`~damage_dolfinx.geometries.Geometry`, a ``(mesh, facet_tags)`` pair, the
            path of a gmsh ``.msh`` file, or a function ``(comm, n)`` returning one of these (a
            mesh family: the only form :func:`~damage_dolfinx.converge` can refine).
        T: final time.
        k: time step (None: the largest below 0.8 k_max and T/100 that divides T; for a
            dynamic model k must be given). A k above the scheme's stability limit k_max is
            refused unless ``allow_unstable``; :meth:`k_max` gives the limit before the run.
        boundaries: ``{role: tag or [tags]}``, a tag a number or a gmsh physical name
            (``{"clamped": "left"}``, a mesh read from gmsh); roles ``clamped`` (u = 0), ``traction``
            (the traction acts there), and one of the model's ``contact_roles``: ``bilateral``
            (u.nu = 0), ``tresca`` (bilateral contact, Tresca friction bound ``g_fric``),
            ``coulomb`` (simplified Coulomb, normal stress ``S_n``, bound ``mu_f |S_n|``),
            ``normal_compliance`` (stiffness ``c_nu``, gap ``gap``). Every tag named must be present on the mesh and non-empty. None: the
            mesh's tags are used as they are (1 clamped, 2 traction, 3 contact).
        params: a :class:`~damage_dolfinx.ModelParameters`, or a dict of changes to the
            model's defaults (:func:`~damage_dolfinx.model_defaults`); unknown names are
            refused, except your own law's data, which go to ``params.extra``.
        traction: ``(x, t) -> UFL vector`` (x the spatial coordinate, t a constant holding
            the time), on the ``traction`` boundary.
        body_force: ``(x, t) -> UFL vector``, the same for the body force.
        zeta0: initial damage, a number or a function of x (NumPy, shape (gdim, N)) in
            [zeta*, 1].
        damage_law: a :class:`~damage_dolfinx.DamageLaw` (None: the thesis law of
            ``params.variant``).
        irreversible: zeta_n <= zeta_{n-1} at every step (the damage step's upper bound).
        n: the level of a mesh family used by :func:`~damage_dolfinx.run`.
        name: the run's name in its records.
        builders: model-specific UFL data, e.g. ``{"friction_bound": lambda x: ...}`` (a
            space-dependent g), ``{"probe": (x, y)}`` (2.2: a history of a point of Gamma_C).
        allow_unstable: run a k above k_max anyway (a warning instead of a refusal).
    """

    model: str
    mesh: object
    T: float
    k: Optional[float] = None
    boundaries: Optional[dict] = None
    params: Union[ModelParameters, dict, None] = None
    traction: Optional[Callable] = None
    body_force: Optional[Callable] = None
    zeta0: Union[float, Callable] = 1.0
    damage_law: Optional[object] = None
    irreversible: bool = False
    n: Optional[int] = None
    name: str = "problem"
    builders: dict = field(default_factory=dict)
    allow_unstable: bool = False
    _checked: bool = field(default=False, repr=False, compare=False)

    # -- what the run machinery reads besides the fields; a catalogue example
    #    (description.Example) holds these as its thesis metadata (fields that take the place
    #    of the class values and of the derived values below, cached_property being overridable)
    own = True              # your problem: a k you give above k_max is refused
    dim = 0                 # the space dimension, known once the mesh is built
    h = None                # the element size of a gmsh mesh family (catalogue)
    mesh_file = None        # a gmsh file replacing the mesh of a catalogue example (--mesh)
    diameter = math.nan     # the body's diameter (nan: taken from the mesh)
    convergence = None      # a default convergence study
    readings = {}           # readings beyond the literal data (none)
    reading = "literal"
    default_reading = "literal"

    @property
    def id(self) -> str:
        """The run's name in its records."""
        return self.name

    @property
    def model_id(self) -> str:
        """The id of the problem's model (``model`` may be the class itself)."""
        return self.model if isinstance(self.model, str) else self.model.id

    @cached_property
    def title(self) -> str:
        from damage_dolfinx.models.registry import model
        return f"{model(self.model).title} (own problem)"

    @cached_property
    def section(self) -> str:
        return self.model_id

    @cached_property
    def assumptions(self) -> list:
        law = self.damage_law.name if self.damage_law is not None else \
            f"thesis variant {getattr(self.params, 'variant', '?')}"
        from damage_dolfinx.models.registry import model
        return [f"own problem, model {self.model_id}: {model(self.model).title}",
                f"damage law: {law}" + (", irreversible (zeta_n <= zeta_{n-1})"
                                        if self.irreversible else "")]

    @cached_property
    def figures(self) -> list:
        return [Figure("fields_final.png", f"{self.name}: von Mises stress and damage")]

    # -- what a model reads of the problem it is built from
    @property
    def geometry(self):
        """The mesh as a :class:`~damage_dolfinx.geometries.Geometry` (a problem on one mesh:
        a Geometry or a ``(mesh, facet_tags)`` pair, as :meth:`build` gives it to the model)."""
        from damage_dolfinx.problem.meshes import as_geometry
        if callable(self.mesh) and not isinstance(self.mesh, tuple):
            raise InputError(f"{self.name}: a mesh family has no geometry until it is built "
                             "(Problem.build or damage_dolfinx.run)")
        return as_geometry(self.mesh)

    @cached_property
    def time(self) -> TimeGrid:
        """The time grid t_n = n k, n = 0 ... T/k."""
        return TimeGrid(float(self.k), float(self.T))

    def k_max(self, comm=None) -> float:
        """The time-step limit of the scheme's explicit terms for this mesh and data (inf: none);
        a k above it is refused. Collective (problem/limits.py)."""
        from damage_dolfinx.problem.limits import k_max
        return k_max(self, comm) if comm is not None else k_max(self)

    def parameters(self) -> ModelParameters:
        """The run's data: the model's defaults with ``params`` applied (validated)."""
        from damage_dolfinx.models.registry import model, validate
        info = model(self.model)
        if isinstance(self.params, ModelParameters):
            p = self.params
        else:
            p = info.defaults()
            changes = dict(self.params or {})
            known = {f.name for f in dataclasses.fields(p)} | set(p.extra)
            own = {key: changes.pop(key) for key in list(changes) if key not in known}
            p = p.replace(**changes)
            if own:  # the user law's data
                if self.damage_law is None:
                    raise InputError(f"unknown parameter(s) {sorted(own)} of model {info.id} "
                                     "(own data are for a damage law, and none is given)")
                p = dataclasses.replace(p, extra={**p.extra, **own})
        p = info.with_roles(p, set(self.boundaries or {}))
        return validate(info, p)

    # -- the stages of a run
    def checked(self) -> "Problem":
        """This problem with every argument validated, before any work (InputError with one
        line otherwise): the data resolved against the model's defaults, k chosen (None: the
        largest below 0.8 k_max and T/100 that divides T), the family level required. Done once:
        a checked problem returns itself."""
        if self._checked:
            return self
        from damage_dolfinx.models.registry import model
        from damage_dolfinx.problem.checks import check_problem
        problem = check_problem(self)  # every argument, before any work (validation.py)
        info = model(problem.model)
        params = problem.parameters()
        k = problem.k
        if k is None:
            if info.dynamic:
                raise InputError(f"model {info.id} needs a time step k below its limit k_max, "
                                 "which depends on the mesh and data: problem.k_max() gives it")
            k = min(problem.T / 100.0, 0.8 * info.k_max(params))
            k = problem.T / math.ceil(problem.T / k * (1 - 1e-12))
        if problem.family and problem.n is None:
            raise InputError("a mesh family (comm, n) -> mesh needs the level n (Problem(n=...))")
        if params.extra.get("stability_check") is not None:
            params = params.replace(stability_check="warn" if problem.allow_unstable else "error")
        return dataclasses.replace(problem, params=params, T=float(problem.T), k=float(k),
                                   n=problem.n if problem.family else None, _checked=True)

    @property
    def family(self) -> bool:
        """Whether ``mesh`` is a mesh family (a function of the ranks and the level)."""
        return callable(self.mesh) and not isinstance(self.mesh, tuple)

    def with_reading(self, name=None) -> "Problem":
        """This problem under reading ``name``: a problem of your own has its data only
        (evidence = literal)."""
        if (name or "literal") not in READINGS:
            raise InputError(f"unknown reading {name!r}; known: {', '.join(READINGS)}")
        return self

    def _resolved(self, overrides):
        """(the problem under the reading named in ``overrides``, overrides without it)."""
        overrides = dict(overrides or {})
        return self.with_reading(overrides.pop("reading", None)), overrides

    def configure(self, n=None, k=None, T=None, h=None, overrides=None, mesh_file=None,
                  comm=None) -> "Problem":
        """The problem as one run has it (validated data, T, k, the mesh level and file), or
        InputError. ``overrides`` may name the reading (key ``reading``). ``comm``: the ranks of
        the run (default all), which the memory check is collective on."""
        ex, overrides = self.checked()._resolved(overrides)  # (as a run checks it)
        return stages.configure(ex, n, k, T, h, overrides, mesh_file, comm)

    def default_k(self, n, h, T, params) -> float:
        """The time step when none is given for the run: the problem's own (an own problem's k
        is its author's choice, decided by :meth:`checked`)."""
        return self.k

    def make_geometry(self, comm, n=None, h=None):
        """The problem's own mesh on ``comm`` (a family at level n)."""
        from damage_dolfinx.problem.meshes import as_geometry
        return as_geometry(self.mesh(comm, n) if self.family else self.mesh, comm)

    def build(self, comm, n=None, k=None, T=None, h=None, overrides=None, mesh_file=None,
              configured=None, contracts=True):
        """The model of one run on ``comm`` (its mesh built, its declarations checked unless
        ``contracts`` is False); ``configured``: what :meth:`configure` returned for the same
        arguments (None: configured here)."""
        return stages.build(configured or self.configure(n, k, T, h, overrides, mesh_file, comm),
                            comm, contracts)

    def problem_data(self, comm, n=None, k=None, T=None, h=None, overrides=None, mesh_file=None,
                     configured=None) -> "Problem":
        """The configured problem on its mesh on ``comm``, checked: what a model is built from
        (no solver set up; the run fingerprint reads it)."""
        return stages.on_mesh(configured or self.configure(n, k, T, h, overrides, mesh_file, comm), comm)

    def mesh_requirements(self):
        """(dimension, facet tags) a --mesh file must have (a catalogue example's)."""
        raise InputError(f"{self.name}: a problem of your own takes its mesh as Problem(mesh=...)")
