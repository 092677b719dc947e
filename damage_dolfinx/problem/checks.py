"""The checks of a :class:`~damage_dolfinx.Problem`'s data, the second half of the validation
layer (:mod:`damage_dolfinx.core.validation` holds the scalars and the other entry points'
arguments): ``check_problem`` before the mesh exists (types, ranges, the model's boundary roles
and data), ``check_data`` once it does (the loads' and the damage law's UFL shapes against the
mesh dimension, evaluated symbolically, and the initial damage at the mesh nodes). Failures
raise :class:`~damage_dolfinx.InputError` naming the argument; every rank refuses alike."""
from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np

from damage_dolfinx.core.parameters import INFINITE_ALLOWED, InputError
from damage_dolfinx.core.validation import (TINY, _shown, flag, is_real, mesh_path_problem, positive,
                                       real, text, whole)


# ---------------------------------------------------------------------------- Problem
def check_problem(problem):
    """The problem with its scalars normalised (NumPy scalars to Python), or InputError.
    Called where the Problem is turned into a run (``Problem.checked``)."""
    from damage_dolfinx.models.laws import DamageLaw
    from damage_dolfinx.models.registry import MODELS, model as model_class
    from damage_dolfinx.core.parameters import ModelParameters
    model = problem.model
    if isinstance(model, np.str_):
        model = str(model)
    if not isinstance(model, (str, type)):
        raise InputError(f"model must be a model id ({', '.join(MODELS)}) or a model class, "
                         f"got {_shown(model)}")
    info = model_class(model)  # InputError for an unknown id
    T = positive("T (final time)", problem.T)
    k = positive("k (time step)", problem.k, allow_none=True)
    if k is not None and k > T * (1 + 1e-12):
        raise InputError(f"k (time step) must not exceed T = {T:g}, got k = {k:g}")
    n = whole("n (mesh level)", problem.n, allow_none=True)
    mesh = problem.mesh
    _check_mesh_argument(mesh)
    roles = _check_boundaries(problem.boundaries, info)
    params = problem.params
    if params is not None and not isinstance(params, (dict, ModelParameters)):
        raise InputError(f"params must be a dict of changes or a ModelParameters "
                         f"(model_defaults({info.id!r})), got {type(params).__name__}")
    if isinstance(params, ModelParameters):
        _check_parameters_of(params, info, problem.damage_law is not None)
    elif isinstance(params, dict):
        params = {_key("params", key): _param_value(key, value) for key, value in params.items()}
    for name in ("traction", "body_force"):
        value = getattr(problem, name)
        if value is not None and not callable(value):
            raise InputError(f"{name} must be a function (x, t) -> UFL vector, got "
                             f"{_shown(value)} ({type(value).__name__})")
    if problem.traction is not None and roles is not None and "traction" not in roles:
        raise InputError("traction is given but no boundary part has the 'traction' role: "
                         "add boundaries={'traction': tag, ...} (else the load acts nowhere)")
    zeta0 = problem.zeta0
    if not callable(zeta0):
        zeta0 = real("zeta0 (initial damage)", zeta0, low=0.0, high=1.0, low_open=True,
                     what="a number in (0, 1] or a function of x")
    if problem.damage_law is not None and not isinstance(problem.damage_law, DamageLaw):
        raise InputError(f"damage_law must be a damage_dolfinx.DamageLaw (DamageLaw(function, "
                         f"name)), got {_shown(problem.damage_law)}")
    irreversible = flag("irreversible", problem.irreversible)
    allow = flag("allow_unstable", problem.allow_unstable)
    name = text("name", problem.name)
    if "/" in name or name in (".", ".."):
        raise InputError(f"name must not contain '/', got {name!r}")
    if not isinstance(problem.builders, dict):
        raise InputError(f"builders must be a dict, got {type(problem.builders).__name__}")
    checked = dataclasses.replace(problem, model=model, T=T, k=k, n=n, params=params,
                                  zeta0=zeta0, irreversible=irreversible,
                                  allow_unstable=allow, name=name)
    zeta_star = checked.parameters().zeta_star
    if not callable(zeta0) and zeta0 < zeta_star:
        raise InputError(f"zeta0 (initial damage) must lie in [zeta_star, 1] = [{zeta_star:g}, "
                         f"1], got {zeta0:g}")
    return checked


def _check_mesh_argument(mesh):
    from damage_dolfinx.core.geometry import Geometry
    if isinstance(mesh, Geometry) or callable(mesh):
        return
    if isinstance(mesh, tuple):
        if len(mesh) != 2:
            raise InputError(f"mesh as a tuple must be (mesh, facet_tags), got {len(mesh)} items")
        return
    if isinstance(mesh, (str, Path)):
        problem = mesh_path_problem(Path(mesh))
        if problem:
            raise InputError(f"mesh file {str(mesh)!r}: {problem}")
        return
    raise InputError("mesh must be a Geometry, a (mesh, facet_tags) pair, a .msh path or a "
                     f"function (comm, n) -> one of these; got {type(mesh).__name__}")


def _check_boundaries(boundaries, info):
    """The roles named, or None (the mesh's own tags)."""
    if boundaries is None:
        return None
    if not isinstance(boundaries, dict) or not boundaries:
        raise InputError("boundaries must be a dict {role: tag or [tags]}, got "
                         f"{_shown(boundaries)}")
    allowed = tuple(info.boundary_roles())  # the model's declaration (Model.boundary_roles)
    for role, tags in boundaries.items():
        if role not in allowed:
            raise InputError(f"boundaries: role {role!r} is not one of model {info.id}'s: "
                             f"{', '.join(allowed)}")
        listed = [tags] if is_real(tags) or isinstance(tags, str) else tags
        if isinstance(listed, (bytes, dict)) or not hasattr(listed, "__iter__"):
            raise InputError(f"boundaries[{role!r}] must be a facet tag, a gmsh physical name "
                             f"or a list of these, got {_shown(tags)}")
        listed = list(listed)
        if not listed:
            raise InputError(f"boundaries[{role!r}] lists no facet tag")
        for tag in listed:
            if isinstance(tag, str):  # a gmsh physical name: looked up on the mesh (meshes.py)
                if not tag.strip():
                    raise InputError(f"boundaries[{role!r}]: an empty physical name")
                continue
            whole(f"boundaries[{role!r}] (a facet tag or a gmsh physical name)", tag, low=0)
    return set(boundaries)


def _key(name, key):
    if not isinstance(key, str) or not key:
        raise InputError(f"{name}: names must be text, got {_shown(key)}")
    return key


def _param_value(key, value):
    """A parameter value: a number (NumPy scalars to Python), a flag or a word."""
    if isinstance(value, (bool, np.bool_)):
        return bool(value)  # checked against the parameter's type (validation.number_like)
    if is_real(value):
        v = float(value) if isinstance(value, (float, np.floating)) else int(value)
        if 0 < abs(v) < TINY:
            raise InputError(f"params[{key!r}] = {v:g} underflows (below {TINY:.3g}, the "
                             "smallest normal number)")
        if isinstance(v, float) and not math.isfinite(v) and not (
                math.isinf(v) and key in INFINITE_ALLOWED):
            allowed = (" (inf is allowed only for " + ", ".join(sorted(INFINITE_ALLOWED)) + ")"
                       if math.isinf(v) else "")
            raise InputError(f"params[{key!r}] must be a finite number, got {v}{allowed}")
        return v
    if isinstance(value, str) or value is None or callable(value):
        return value
    raise InputError(f"params[{key!r}] must be a number, a flag or a word, got "
                     f"{_shown(value)} ({type(value).__name__})")


def _check_parameters_of(params, info, own_law):
    """A ModelParameters built for another model (model_defaults('3.3') given to a 2.2
    problem) lacks this model's data, or carries data the model does not read (allowed only as
    the data of one's own damage law)."""
    own = info.defaults()
    missing = sorted(set(own.extra) - set(params.extra))
    if missing:
        raise InputError(f"params: a ModelParameters without model {info.id}'s data "
                         f"({', '.join(missing)}); start from model_defaults({info.id!r})")
    # the model reads its defaults' data and every datum it has a rule for (Model.data_rules:
    # its own, e.g. 3.3's initial_damage, and those shared by the models, e.g. history_every)
    foreign = sorted(set(params.extra) - set(own.extra) - set(info.data_rules()))
    if foreign and not own_law:
        raise InputError(f"params: a ModelParameters with data model {info.id} does not read "
                         f"({', '.join(foreign[:6])}{', ...' if len(foreign) > 6 else ''}): "
                         f"another model's? start from model_defaults({info.id!r})")


# ---------------------------------------------------------------------------- with the mesh
def check_data(data):
    """The loads, the damage law, the initial damage and the boundary parts against the mesh
    (called once the geometry exists, before any solver is set up): shapes from the UFL
    expressions the user's functions build, evaluated symbolically. The user's functions run on
    each rank with no collective call in between; one exchange then decides for every rank (a
    function that raises on one rank only is refused on all of them alike, nobody waits)."""
    comm = data.geometry.mesh.comm
    error, stats = None, (0, np.inf, -np.inf)
    try:
        stats = _local_checks(data)
    except InputError as exc:
        error = str(exc)
    decided = comm.allgather((error, stats))
    errors = [e for e, _ in decided if e is not None]
    if errors:
        raise InputError(errors[0])
    if data.traction is not None:
        from damage_dolfinx.problem.meshes import tag_counts
        from damage_dolfinx.models.registry import TRACTION
        if not tag_counts(data.geometry).get(TRACTION):
            raise InputError("traction is given but the mesh has no boundary part with the "
                             f"traction role (tag {TRACTION}): name it in boundaries")
    if callable(data.zeta0):
        bad = sum(s[0] for _, s in decided)
        lo, hi = min(s[1] for _, s in decided), max(s[2] for _, s in decided)
        if bad:
            raise InputError(f"zeta0(x) must be finite at every mesh node, got NaN or inf at "
                             f"{bad} node(s)")
        zs = data.params.zeta_star
        if not (np.isfinite(lo) and np.isfinite(hi)) or lo < zs - 1e-12 or hi > 1.0 + 1e-12:
            raise InputError(f"zeta0(x) must lie in [zeta_star, 1] = [{zs:g}, 1] at every mesh "
                             f"node, got values in [{lo:.4g}, {hi:.4g}]")


def _local_checks(data) -> tuple:
    """check_data's work on this rank alone: the shapes of the loads and the law, zeta0(x) at
    this rank's nodes; returns (non-finite count, min, max) of those values."""
    import ufl
    from damage_dolfinx.models.laws import THESIS_A, THESIS_B
    msh = data.geometry.mesh
    gdim = msh.geometry.dim
    x = ufl.SpatialCoordinate(msh)
    t = _time_constant(msh)
    for name in ("traction", "body_force"):
        fn = getattr(data, name)
        if fn is None:
            continue
        value = _call(name, "(x, t)", fn, x, t)
        _expect_shape(name, value, (gdim,), f"a UFL vector of {gdim} components "
                      f"(ufl.as_vector(({', '.join(['...'] * gdim)})))")
    law = data.damage_law
    if law is not None and law not in (THESIS_A, THESIS_B):
        e = ufl.sym(ufl.outer(x, x))
        z = x[0] * 0 + t + 1.0
        value = _call(f"damage_law {law.name!r}", "(eps, zeta, params)", law, e, z, data.params)
        _expect_shape(f"damage_law {law.name!r}", value, (), "a UFL scalar")
    z0 = data.zeta0
    if not callable(z0):
        return 0, np.inf, -np.inf
    pts = np.ascontiguousarray(msh.geometry.x.T)  # the mesh nodes, where P1 takes zeta0
    pts = pts[:gdim] if gdim < 3 else pts
    try:
        values = np.asarray(z0(pts), dtype=float)
    except Exception as exc:  # noqa: BLE001 - a user function: named, one line
        raise InputError(f"zeta0(x) raised {type(exc).__name__}: {exc} (x: a NumPy array of "
                         f"shape ({gdim}, N))") from None
    if values.shape not in ((pts.shape[1],), (1, pts.shape[1])):
        raise InputError(f"zeta0(x) must return one value per point (shape (N,)), got "
                         f"shape {values.shape} for N = {pts.shape[1]}")
    finite = values[np.isfinite(values)]
    return (int(values.size - finite.size), float(finite.min()) if finite.size else np.inf,
            float(finite.max()) if finite.size else -np.inf)


def _time_constant(msh):
    from damage_dolfinx import compat  # noqa: F401 - fem.Constant is the same everywhere
    from dolfinx import fem
    return fem.Constant(msh, 0.0)


def _call(name, signature, fn, *args):
    try:
        return fn(*args)
    except InputError:
        raise
    except Exception as exc:  # noqa: BLE001 - a user function: named, one line
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
        raise InputError(f"{name}{signature} cannot be built from UFL arguments: "
                         f"{type(exc).__name__}: {first}") from None


def _expect_shape(name, value, shape, expected):
    import ufl
    from ufl.core.expr import Expr
    if isinstance(value, (tuple, list)):
        raise InputError(f"{name} must return {expected}, got a {type(value).__name__} "
                         "(wrap it in ufl.as_vector)")
    if is_real(value) and shape == ():
        return
    if not isinstance(value, Expr):
        raise InputError(f"{name} must return {expected}, got {_shown(value)} "
                         f"({type(value).__name__})")
    if value.ufl_shape != shape or value.ufl_free_indices:
        got = "a scalar" if value.ufl_shape == () else f"shape {value.ufl_shape}"
        raise InputError(f"{name} must return {expected}, got {got}")
    del ufl


