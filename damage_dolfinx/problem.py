"""Your own problem: one of the models on your mesh, with your boundary parts, loads, data and
damage law. Run it with :func:`damage_dolfinx.run` (summary.json, XDMF, history.csv, checkpoints
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
from typing import Callable, Optional, Union

from damage_dolfinx.parameters import InputError, ModelParameters


@dataclass
class Problem:
    """One of the models on your mesh, with your data.

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

    def k_max(self, comm=None) -> float:
        """The time-step limit of the scheme's explicit terms for this mesh and data (inf: none);
        a k above it is refused. Collective (runtime/limits.py)."""
        from damage_dolfinx.runtime.limits import k_max
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

    def example(self):
        """The run description the run machinery takes (internal)."""
        from damage_dolfinx.description import Example, Figure
        from damage_dolfinx.laws import DamageLaw
        from damage_dolfinx.meshes import as_geometry
        from damage_dolfinx.models.registry import model
        from damage_dolfinx.validation import check_problem
        self = check_problem(self)  # every argument, before any work (validation.py)
        info = model(self.model)
        if self.damage_law is not None and not isinstance(self.damage_law, DamageLaw):
            raise InputError("damage_law must be a damage_dolfinx.DamageLaw "
                             "(DamageLaw(function, name))")
        if not (isinstance(self.T, (int, float)) and math.isfinite(self.T) and self.T > 0):
            raise InputError(f"final time T must be a positive number, got T = {self.T!r}")
        params = self.parameters()
        k = self.k
        if k is None:
            if info.dynamic:
                raise InputError(f"model {info.id} needs a time step k below its limit k_max, "
                                 "which depends on the mesh and data: problem.k_max() gives it")
            k = min(self.T / 100.0, 0.8 * info.k_max(params))
            k = self.T / math.ceil(self.T / k * (1 - 1e-12))
        family = callable(self.mesh) and not isinstance(self.mesh, tuple)
        n = self.n if family else None
        if family and n is None:
            raise InputError("a mesh family (comm, n) -> mesh needs the level n (Problem(n=...))")
        mesh = self.mesh

        def make_geometry(comm, n_, h_):
            return as_geometry(mesh(comm, n_) if family else mesh, comm)

        if params.extra.get("stability_check") is not None:
            params = params.replace(stability_check="warn" if self.allow_unstable else "error")
        law = self.damage_law.name if self.damage_law is not None else \
            f"thesis variant {params.variant}"
        return Example(
            id=self.name, title=f"{info.title} (own problem)", section=info.id, params=params,
            T=float(self.T), k=float(k), make_geometry=make_geometry, model=info,
            diameter=math.nan, n=n, dim=0, body_force=self.body_force, traction=self.traction,
            zeta0=self.zeta0, builders=dict(self.builders), damage_law=self.damage_law,
            irreversible=bool(self.irreversible), boundaries=self.boundaries, own=True,
            allow_unstable=bool(self.allow_unstable),
            assumptions=[f"own problem, model {info.id}: {info.title}",
                         f"damage law: {law}" + (", irreversible (zeta_n <= zeta_{n-1})"
                                                 if self.irreversible else "")],
            figures=[Figure("fields_final.png", f"{self.name}: von Mises stress and damage")],
            reading="literal")
