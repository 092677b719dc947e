"""A model, the one unit that knows a scheme: :class:`Model` (the base every model derives from).

A model class declares what the rest of the package reads from it, and nothing else is written
about it anywhere:

* ``id``, ``title``: its name in the registry and the records;
* ``contact_roles``: what its contact boundary Gamma_C may mean (``tresca``, ...);
* ``dynamic``: whether it has inertia (its k_max depends on the mesh: k must be given);
* ``stability_limit``: what limits k (``""``: nothing), and :meth:`Model.k_max` for the
  quasistatic schemes whose limit is closed-form;
* :meth:`Model.defaults` (typed default data) and :meth:`Model.check` (their validation);
* ``checkpoint_fields``: the attributes (Functions) that a checkpoint holds;
* ``history_columns``: the scalars it adds to history.csv (every one must be written);
* ``old_state`` (the (Function, copy) pairs a step starts from) and ``update`` (the explicit
  update after the sub-steps, e.g. u_n = u_{n-1} + k v_n);
* :meth:`Model.scheme`: its sub-steps in order (:class:`SubStep`: name, solver kind, PETSc
  prefix, solve callable, the history keys of its iteration count);
* in its constructor the unknowns (``self.u``, ``self.zeta``, ...) and ``self.output_fields``.

One generic time loop (``runtime/loop.py``, or :func:`damage_dolfinx.steps`) runs any model:
:meth:`Model.initialize` (t = 0), then :meth:`Model.advance` per step, which is the same for
every model: copy the old state, run the sub-steps in order (timed, their counts collected),
apply the explicit update. A scheme that needs more has two hooks, :meth:`Model.begin_step` and
:meth:`Model.end_step`, and says why in its docstring. The initial state is the shared one
(zeta_0, u_0 = v_0 = 0) plus :meth:`Model.start`; a model implements ``update_output()``.
"""
from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from damage_dolfinx import compat
from damage_dolfinx.forms.constitutive import eps
from damage_dolfinx.core.parameters import InputError, ModelParameters
from damage_dolfinx.numerics.solvers import SolveContext
from damage_dolfinx.models.reporting import Reporting

#: the damage data of the obstacle-inclusion models' defaults (variant A, (1.3))
DAMAGE_A = dict(kappa=1e-2, zeta_star=0.01, q_star=1000.0, variant="A", lam_D=0.1, lam_u=1000.0,
                lam_w=0.0, L_trunc=1000.0, stop_at_zeta_star=False)

#: a load builder: (x = SpatialCoordinate, t = fem.Constant) -> UFL vector
LoadBuilder = Callable[[object, object], object]


@dataclass(frozen=True)
class SubStep:
    """One sub-step of a scheme: its ``name`` (its wall time goes to ``timings[name]``), the
    ``kind`` of solve (``linear``, ``snes-vi`` with bounds, ``newton`` on a regularised law,
    ``semismooth`` Newton, ``update`` for an explicit formula), its PETSc options ``prefix``, the
    ``solve`` callable (no argument; returns its iteration count, or None; None: the sub-step is
    switched off and counts 0 iterations), and ``its``: the history keys its count goes under."""
    name: str
    kind: str
    prefix: str
    solve: Optional[Callable[[], Optional[int]]]
    its: tuple = ()


class Model(Reporting):
    """Base of the models: the time level, the solve context and the declarations (the common
    scalars, contact resultant and mesh information: :class:`~damage_dolfinx.models.reporting.Reporting`).

    Subclasses create ``self.u`` (displacement), ``self.zeta`` and ``self.zeta_old`` (damage)
    and ``self.von_mises`` (DG0), declare :meth:`scheme` (the sub-steps), implement
    ``update_output()``, and list output fields in ``self.output_fields``. Hooks for
    problem-specific output: ``history_columns`` (keys that
    ``scalars()`` or the step stats add to history.csv; an instance may set
    ``extra_history_columns`` when they depend on the data) and ``summary_extra()`` (keys added
    to summary.json).
    """

    #: the model's id in the registry (None: an abstract base)
    id: Optional[str] = None
    title: str = ""
    #: the contact roles its Gamma_C may play (boundary role names)
    contact_roles: tuple = ()
    #: boundary roles of its own beyond clamped, traction and contact: {role: facet tag the
    #: model reads} (tags other than 1, 2, 3)
    extra_roles: dict = {}
    #: inertia: k must be given (the limit depends on the mesh)
    dynamic: bool = False
    #: what limits k ("" when nothing does)
    stability_limit: str = ""
    #: True: the model compares k with its mesh-dependent limit itself (the package's dynamic
    #: models, by their datum stability_check); otherwise the run compares k with
    #: :meth:`mesh_k_max` once the model is built
    checks_time_step: bool = False
    #: the Functions (attribute names) a checkpoint holds, in order
    checkpoint_fields: tuple = ("u", "zeta")
    #: the scalars this model adds to history.csv
    history_columns: tuple = ()
    #: bounds of fields of its own, {attribute: (lo, hi)} (e.g. an adhesion field in [0, 1]):
    #: the state check after every step stops the run when one is left by more than 1e-6
    state_bounds: dict = {}
    #: the old state a step starts from: (Function, its copy) attribute pairs, copied first
    old_state: tuple = (("u", "u_old"), ("zeta", "zeta_old"))
    #: the explicit update after the sub-steps, (new, old, rate): new = old + k rate
    #: (e.g. ("u", "u_old", "v"): u_n = u_{n-1} + k v_n); None: none
    update: Optional[tuple] = None
    #: the rules of the model's own data in ``params.extra`` (name -> (test, what it must
    #: be)); a subclass adds its own and keeps its parents' (:meth:`data_rules`)
    rules: dict = {}
    #: quadrature degree of the contact integrals (None: estimated from the integrand); the
    #: contact resultant uses the scheme's, so that it balances the load exactly
    contact_quadrature_degree: Optional[int] = None

    # -- the declarations a run reads before building anything
    @classmethod
    def defaults(cls) -> ModelParameters:
        """The model's default data (a generic starting point, docs/models.md)."""
        raise NotImplementedError(f"model {cls.id} declares no default data")

    @classmethod
    def data_rules(cls) -> dict:
        """The rules of the data shared by the models (core.parameters.EXTRA_RULES) and those
        of this model's classes, the nearest class last."""
        from damage_dolfinx.core.parameters import EXTRA_RULES
        merged = dict(EXTRA_RULES)
        for klass in reversed(cls.__mro__):
            merged.update(vars(klass).get("rules", {}))
        return merged

    @classmethod
    def check(cls, params: ModelParameters) -> ModelParameters:
        """The model's checks of its data (after ``params.validate()``); returns them."""
        return params

    @classmethod
    def k_max(cls, params: ModelParameters) -> float:
        """The closed-form stability limit of a quasistatic scheme with an explicit term
        (inf: none, or mesh-dependent, checked when the model is built)."""
        return math.inf

    def mesh_k_max(self) -> Optional[float]:
        """The stability limit of k on this model's mesh with its data (a dynamic scheme's
        explicit terms), computed in the constructor (e.g. with ``blocks.estimate_k_max``);
        None: no limit. ``Problem.k_max()`` builds the model and returns it (inf for None);
        ``dd.check_model`` compares it with an eigenvalue estimate. The package's dynamic models
        keep it in ``self.stability["k_max"]`` (3.1, 3.3) or an instance ``k_max`` (3.2), read
        here; a model of your own overrides this method."""
        stability = getattr(self, "stability", None)
        if isinstance(stability, dict):
            return stability.get("k_max")
        if "k_max" in vars(self):  # an instance attribute, not the classmethod
            return vars(self)["k_max"]
        if self.dynamic:
            raise NotImplementedError(
                f"model {self.id} is dynamic (its stability limit depends on the mesh) but does "
                "not give it: implement mesh_k_max(self) (a number, or None: no limit)")
        return None

    def __init_subclass__(cls, **kwargs):
        """A model's own ``k_max`` is checked wherever it is asked for (validation.limit: a
        NaN, a negative or a non-number limit is refused, never compared: k > NaN is False)."""
        super().__init_subclass__(**kwargs)
        own = cls.__dict__.get("k_max")
        if isinstance(own, classmethod) and not getattr(own.__func__, "_checked_limit", False):
            raw = own.__func__

            def k_max(klass, params, _raw=raw):
                from damage_dolfinx.core.validation import limit
                return limit("k_max", _raw(klass, params), f"model {klass.__name__}")
            k_max._checked_limit = True
            k_max.__doc__, k_max.__name__ = raw.__doc__, "k_max"
            k_max.__wrapped__ = raw
            cls.k_max = classmethod(k_max)

    @classmethod
    def boundary_roles(cls) -> dict:
        """role -> the facet tag the model reads there: ``clamped`` 1 (Gamma_D), ``traction`` 2
        (Gamma_N), each of ``contact_roles`` 3 (Gamma_C), and ``extra_roles``."""
        from damage_dolfinx.core.tags import GAMMA_C, GAMMA_D, GAMMA_N
        return {"clamped": GAMMA_D, "traction": GAMMA_N,
                **{role: GAMMA_C for role in cls.contact_roles}, **cls.extra_roles}

    @classmethod
    def with_roles(cls, params: ModelParameters, roles: set) -> ModelParameters:
        """The data as the boundary roles named by a problem select them (default: as given)."""
        return params

    @classmethod
    def declared_columns(cls, problem, dim: int) -> list:
        """The history columns an instance built for ``problem`` (a configured Problem: its
        ``builders``) on a mesh of dimension ``dim`` declares before the run attaches its
        contact outputs (its ``extra_history_columns`` after the constructor), known before
        anything is built (the sweep refuses a plot of a scalar no point reports with it).
        A model whose columns depend on the data overrides it."""
        return list(cls.history_columns)

    @property
    def extra_history_columns(self) -> list:
        return list(getattr(self, "_history_columns", None) or self.history_columns)

    @extra_history_columns.setter
    def extra_history_columns(self, columns):
        self._history_columns = list(columns)

    def scheme(self) -> tuple:
        """The scheme's sub-steps in order (:class:`SubStep`), each with its solve callable;
        asked once, at the first step (the model is complete then)."""
        return ()

    def __init__(self, data):
        if not isinstance(data.params, ModelParameters):  # a Problem built by hand
            data = dataclasses.replace(data, params=data.parameters())
        self.data, self.params = data, data.params
        self.mesh = data.geometry.mesh
        self.comm = self.mesh.comm
        self.context = SolveContext(example=data.id)
        self.n, self.t = 0, 0.0
        self.t_const = fem.Constant(self.mesh, 0.0)
        self.output_fields = []
        self.timings = {}  # seconds per sub-step, whole run
        self._plan = None

    @property
    def error_components(self) -> list:
        """(name, Function, norm) summed in convergence errors; norm "V" = ||eps(.)||_L2 or
        "L2". Default: ||u||_V + ||zeta||_Y (Cor. 2.1); problems assign their own."""
        return getattr(self, "_error_components", None) or [("u", self.u, "V"),
                                                             ("zeta", self.zeta, "L2")]

    @error_components.setter
    def error_components(self, components):
        self._error_components = list(components)

    # -- checkpoint/restart (checkpoint.py)
    #: steppers whose state is more than Functions (e.g. the bridge's failure record) set False
    checkpoint_supported = True

    def checkpoint_state(self) -> dict:
        """name -> Function: everything the next step reads: ``checkpoint_fields``, and the
        Function of each ``old_state`` pair (what the next step starts from) by construction,
        also when ``checkpoint_fields`` leaves it out. Models with more state extend this (and
        are refused when they leave an ``old_state`` Function out: models/contracts.py)."""
        names = list(self.checkpoint_fields)
        names += [new for new, _ in self.old_state if new not in names]
        return {name: getattr(self, name) for name in names}

    def restore(self, n: int):
        """Continue from time level n after checkpoint.load() has set checkpoint_state()."""
        self._set_time(n)
        self._forget_norms()

    def _forget_norms(self):
        """The products the scalars carry from step to step start afresh (a loaded state)."""
        norms = getattr(self, "_field_norms", None)
        if norms is not None:
            norms.forget()

    # -- time loop interface
    def initialize(self) -> dict:
        """t = 0: zeta_0 (u_0 = v_0 = 0, the Functions' initial value), then :meth:`start`."""
        self._set_time(0)
        self._forget_norms()
        self.initial_damage()
        self.zeta_old.x.array[:] = self.zeta.x.array
        return self.start()

    def initial_damage(self):
        """zeta_0 into ``self.zeta`` (checked to lie in [zeta*, 1])."""
        self.interpolate_zeta0(self.zeta)

    def start(self) -> dict:
        """What the scheme does at t = 0 after zeta_0 (e.g. the initial elastic solve); its
        solver counts."""
        return {}

    def advance(self) -> dict:
        """One step t_{n-1} -> t_n, the same for every model: :meth:`begin_step`, the old state
        copied (``old_state``), the sub-steps of ``scheme`` in order (each timed into
        ``timings[name]``, its iteration count under its ``its`` keys), the explicit update
        (``update``), then :meth:`end_step`. Returns the iteration counts."""
        self._set_time(self.n + 1)
        if self._plan is None:
            self._plan = self._step_plan()
        copies, steps, update = self._plan
        self.begin_step()
        for new, old in copies:
            old[:] = new
        stats, timings, clock = {}, self.timings, time.perf_counter
        for name, solve, keys in steps:
            if solve is None:
                its = 0
            else:
                start = clock()
                its = solve()
                timings[name] += clock() - start
            for key in keys:
                stats[key] = its
        if update is not None:
            new, old, rate = update
            np.add(old, self.data.time.k * rate, out=new)
        self.end_step(stats)
        return stats

    def _step_plan(self):
        """The arrays and callables of :meth:`advance`, looked up once (the Functions' value
        arrays are views that stay valid)."""
        array = lambda name: getattr(self, name).x.array  # noqa: E731
        copies = [(array(new), array(old)) for new, old in self.old_state]
        steps = []
        for s in self.scheme():
            self.timings.setdefault(s.name, 0.0)
            steps.append((s.name, s.solve, tuple(s.its)))
        update = tuple(array(name) for name in self.update) if self.update else None
        return copies, steps, update

    def begin_step(self):
        """What a scheme does before the old state is copied (none by default)."""

    def end_step(self, stats: dict):
        """What a scheme does after its explicit update (none by default)."""

    def _set_time(self, n):
        self.n, self.t = n, self.data.time.t(n)
        self.t_const.value = self.t
        self.context.step, self.context.t = n, self.t

    @property
    def num_steps(self) -> int:
        return self.data.time.num_steps

    def stop_reason(self) -> Optional[str]:
        """Why the run must stop early (``stop_at_zeta_star``), or None."""
        if self.params.stop_at_zeta_star and self.zeta_min() <= self.params.zeta_star:
            return "zeta_star_reached"
        return None

    # -- helpers for subclasses
    def obstacle_damage_step(self, prefix="damage_"):
        """The damage inclusion step of 2.2, 2.4 and 3.1-3.3 (docs/models.md, "The damage step"):
        zeta_n in K^h from zeta_{n-1} and the explicit source phi(eps(u_{n-1}), zeta_{n-1}), SNES
        vinewtonrsls. Needs ``self.u_old``, ``self.zeta`` and ``self.zeta_old``."""
        from damage_dolfinx.numerics.damage import DamageStep
        p, msh = self.params, self.mesh
        phi_old = self.damage_source(eps(self.u_old), self.zeta_old)
        step = DamageStep(self.zeta, self.zeta_old, phi_old, fem.Constant(msh, self.data.time.k),
                          fem.Constant(msh, float(p.kappa)), self.context, obstacle=True,
                          zeta_star=p.zeta_star, prefix=prefix,
                          irreversible=self.data.irreversible)
        # the explicit source reads u_{n-1}: u_old must be the copy of u (contracts.py)
        step.previous_state = step.previous_state + ((self.u, self.u_old),)
        return step

    def damage_source(self, e, z):
        """The damage source phi(e, z) of this run: the user's law, or the thesis law (1.3) or
        (1.4) of ``params.variant``."""
        from damage_dolfinx.models.laws import thesis_law
        law = self.data.damage_law or thesis_law(self.params.variant)
        return law(e, z, self.params)

    def _timed(self, key, fn, *args):
        """fn(*args), its wall time added to self.timings[key]."""
        start = time.perf_counter()
        out = fn(*args)
        self.timings[key] += time.perf_counter() - start
        return out

    def interpolate_zeta0(self, zeta):
        z0 = self.data.zeta0
        if callable(z0):
            compat.interpolate(zeta, z0)
        else:
            zeta.x.array[:] = float(z0)
        owned = zeta.x.array[:zeta.function_space.dofmap.index_map.size_local]
        lo = self.comm.allreduce(owned.min() if owned.size else np.inf, op=MPI.MIN)
        hi = self.comm.allreduce(owned.max() if owned.size else -np.inf, op=MPI.MAX)
        if lo < self.params.zeta_star - 1e-12 or hi > 1.0 + 1e-12:
            raise InputError(f"initial damage must lie in [zeta_star, 1] = [{self.params.zeta_star}, 1]; "
                             f"got values in [{lo:.4g}, {hi:.4g}]")

    def loads(self):
        """(f_B, f_N) as UFL expressions of x and the time constant (None where absent)."""
        x = ufl.SpatialCoordinate(self.mesh)
        f_B = self.data.body_force(x, self.t_const) if self.data.body_force else None
        f_N = self.data.traction(x, self.t_const) if self.data.traction else None
        return f_B, f_N
