"""The contracts between a model's declarations and what it builds, checked when the model is
built (before any step), for the package's models and for a model of your own alike.

* the declarations have their form (name pairs, name tuples, bounds lo <= hi), checked on
  the class before it is built (:func:`declaration_problems`);
* every name of ``old_state``, ``update``, ``checkpoint_fields`` and ``state_bounds`` is a
  Function of the built model, each ``old_state`` pair two Functions of one space;
* what a step reads from the previous one is in the checkpoint: each Function ``new`` of an
  ``old_state`` pair (its value at the end of step n is what step n+1 starts from) is among
  :meth:`Model.checkpoint_state` (the base class adds it by construction; a model that
  overrides ``checkpoint_state`` and leaves one out is refused);
* the state a package block reads from the previous step is declared: a block holding
  ``previous_state`` (the damage step: (zeta, zeta_old), and (u, u_old) for the explicit
  source of ``obstacle_damage_step``) needs each of its (new, old) pairs in ``old_state``;
* the PETSc prefix of each :class:`SubStep` is that of the solver its ``solve`` calls, where
  the solver can be seen (a bound ``solve`` of a package solver, or a ``partial`` of one);
* a dynamic model gives its mesh-dependent stability limit through :meth:`Model.mesh_k_max`
  (a positive number, or None: none).

:func:`state_functions` is the list of Functions the run checks after every step (finite, and
zeta within its bounds): everything a model holds as state, from its declarations.
"""
from __future__ import annotations

import functools
import math

from dolfinx import fem

from damage_dolfinx.core.parameters import InputError


class ContractError(InputError):
    """A model's declarations disagree with what it builds (refused before any step)."""


def _function(model, name, what):
    f = getattr(model, name, None)
    if not isinstance(f, fem.Function):
        raise ContractError(f"model {model.id}: {what} names {name!r}, which is "
                            f"{'not set' if f is None else 'not a dolfinx Function'} on the "
                            "built model (create it in __init__)")
    return f


def _names(value) -> bool:
    """A tuple or list of non-empty strings (a bare string is not: it would be read letter by
    letter)."""
    return isinstance(value, (tuple, list)) and all(isinstance(v, str) and v for v in value)


def declaration_problems(model) -> list:
    """What is wrong with the form of the declarations of ``model`` (a Model class before it is
    built, or a built model): ``old_state`` (name pairs), ``update`` (None or three names),
    ``checkpoint_fields`` and ``history_columns`` (tuples of names), ``state_bounds`` ({name:
    (lo, hi)}, lo <= hi, no NaN). Checked before the model is built, so that a mistake there
    is named, not met as an error inside the constructor."""
    mid, out = getattr(model, "id", "?"), []
    old_state = getattr(model, "old_state", ())
    if not isinstance(old_state, (tuple, list)):
        out.append(f"model {mid}: old_state is {old_state!r}, not a tuple of (Function, copy) "
                   "pairs of attribute names, e.g. (('u', 'u_old'), ('zeta', 'zeta_old'))")
    else:
        for pair in old_state:
            if not (isinstance(pair, (tuple, list)) and len(pair) == 2 and _names(pair)):
                out.append(f"model {mid}: old_state holds {pair!r}, not a (Function, copy) pair "
                           "of attribute names, e.g. ('u', 'u_old')")
            elif pair[0] == pair[1]:
                out.append(f"model {mid}: old_state pairs {pair[0]!r} with itself: the copy "
                           "must be a Function of its own, e.g. "
                           f"({pair[0]!r}, {pair[0] + '_old'!r})")
    update = getattr(model, "update", None)
    if update is not None and not (isinstance(update, (tuple, list)) and len(update) == 3
                                   and _names(update)):
        out.append(f"model {mid}: update is {update!r}, not None or (new, old, rate) attribute "
                   "names, e.g. ('u', 'u_old', 'v')")
    for what in ("checkpoint_fields", "history_columns"):
        value = getattr(model, what, ())
        if not _names(value):
            out.append(f"model {mid}: {what} is {value!r}, not a tuple of names, e.g. "
                       f"({value!r},)" if isinstance(value, str) else
                       f"model {mid}: {what} is {value!r}, not a tuple of names")
    bounds = getattr(model, "state_bounds", None) or {}
    if not isinstance(bounds, dict):
        out.append(f"model {mid}: state_bounds is {bounds!r}, not a dict {{attribute: (lo, hi)}}")
        return out
    for name, pair in bounds.items():
        ok = (isinstance(name, str) and isinstance(pair, (tuple, list)) and len(pair) == 2
              and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in pair))
        if not ok:
            out.append(f"model {mid}: state_bounds[{name!r}] is {pair!r}, not a pair of numbers "
                       "(lo, hi), e.g. (0.0, 1.0) (-inf or inf: no bound)")
        elif any(math.isnan(v) for v in pair) or pair[0] > pair[1]:
            out.append(f"model {mid}: state_bounds[{name!r}] is {tuple(pair)!r}: lo <= hi, "
                       "neither NaN, are needed")
    return out


def checkpoint_functions(model) -> dict:
    """name -> Function of the checkpoint (the NumPy solver state left out); {} when the model
    has no checkpoints."""
    if not getattr(model, "checkpoint_supported", True):
        return {}
    try:
        state = model.checkpoint_state()
    except InputError:  # a variant without checkpoints (2.3 memory_mode=sum)
        return {}
    return {name: f for name, f in state.items() if isinstance(f, fem.Function)}


def state_functions(model) -> list:
    """(name, Function) of everything the model holds as state, each Function once: u and
    zeta, what it checkpoints, both sides of ``old_state``, the names of ``update``, and its
    ``output_fields``."""
    seen, out = set(), []

    def add(name, f):
        if isinstance(f, fem.Function) and id(f) not in seen:
            seen.add(id(f))
            out.append((name, f))
    for name in ("u", "zeta"):
        add(name, getattr(model, name, None))
    for name, f in checkpoint_functions(model).items():
        add(name, f)
    for pair in model.old_state:
        for name in pair:
            add(name, getattr(model, name, None))
    for name in model.update or ():
        add(name, getattr(model, name, None))
    for f in getattr(model, "output_fields", ()) or ():
        add(getattr(f, "name", "output"), f)
    return out


def _solver_prefix(solve):
    """The PETSc prefix of the package solver a sub-step's ``solve`` calls (None: not seen)."""
    while isinstance(solve, functools.partial):
        solve = solve.func
    owner = getattr(solve, "__self__", None)
    if owner is None:
        return None
    from damage_dolfinx.models.base import Model
    if isinstance(owner, Model):  # a method of the model: its solvers are not seen
        return None
    for holder in (owner, getattr(owner, "snes", None), getattr(owner, "linear", None),
                   getattr(owner, "newton", None)):
        prefix = getattr(holder, "prefix", None)
        if isinstance(prefix, str):
            return prefix
    return None


def _error_component_problems(model) -> list:
    """What is wrong with ``error_components`` (what a convergence study measures): each a
    (name, Function, norm) triple, the names distinct, the norm one of ``viz.post.NORMS``; a
    mistake found here is found before a study's reference run, not after it."""
    from damage_dolfinx.viz.post import NORMS
    mid, out, names = model.id, [], set()
    try:
        components = list(model.error_components)
    except TypeError:
        return [f"model {mid}: error_components is not a list of (name, Function, norm)"]
    for entry in components:
        if not (isinstance(entry, (tuple, list)) and len(entry) == 3):
            out.append(f"model {mid}: error_components holds {entry!r}, not a (name, "
                       "Function, norm) triple")
            continue
        name, f, norm = entry
        if not (isinstance(name, str) and name):
            out.append(f"model {mid}: error_components: the name {name!r} is not a non-empty "
                       "string")
        elif name in names:
            out.append(f"model {mid}: error_components: the name {name!r} is given twice")
        else:
            names.add(name)
        if not hasattr(getattr(f, "x", None), "array") or not hasattr(f, "function_space"):
            out.append(f"model {mid}: error_components: {name!r} is a "
                       f"{type(f).__name__}, not a dolfinx.fem.Function")
        if norm not in NORMS:
            out.append(f"model {mid}: error_components: {name!r} has the norm {norm!r}; "
                       f"the norms are {', '.join(NORMS)}")
    if not components:
        out.append(f"model {mid}: error_components is empty: a convergence study would "
                   "measure nothing")
    return out


def check(model):
    """Raise ContractError naming the first declaration the built ``model`` breaks."""
    found = problems(model)
    if found:
        raise ContractError(found[0][1])


def problems(model) -> list:
    """(check, message) for each declaration the built ``model`` breaks, check one of
    ``declarations``, ``previous_state``, ``checkpoint``, ``prefixes``, ``stability_limit``."""
    mid = model.id
    found = [("declarations", m) for m in declaration_problems(model)]
    if found:
        return found
    pairs = []
    for pair in model.old_state:
        try:
            new, old = (_function(model, name, "old_state") for name in pair)
        except ContractError as exc:
            found.append(("declarations", str(exc)))
            continue
        if new.x.array.shape != old.x.array.shape or new is old:
            found.append(("declarations", f"model {mid}: old_state pairs {pair[0]!r} with "
                          f"{pair[1]!r}, {'the same Function' if new is old else 'a Function of another space'}: "
                          "the copy must be a Function of its own on the same space"))
            continue
        pairs.append((pair[0], new, old))
    for name in model.update or ():
        try:
            _function(model, name, "update")
        except ContractError as exc:
            found.append(("declarations", str(exc)))
    if getattr(model, "checkpoint_supported", True):
        for name in model.checkpoint_fields:
            try:
                _function(model, name, "checkpoint_fields")
            except ContractError as exc:
                found.append(("declarations", str(exc)))
    for name in model.state_bounds or {}:
        try:
            _function(model, name, "state_bounds")
        except ContractError as exc:
            found.append(("declarations", str(exc)))
    if found:  # a name that is no Function: the checks below would meet it as an error
        return found
    found += [("declarations", m) for m in _error_component_problems(model)]
    # what the package's blocks read from the previous step is declared
    declared = {(id(a), id(b)) for _, a, b in pairs}

    def name_of(f):
        return next((k for k, v in vars(model).items() if v is f), f.name)
    for attr, value in list(vars(model).items()):
        for new, old in getattr(value, "previous_state", ()) or ():
            if (id(new), id(old)) not in declared:
                found.append(("previous_state",
                              f"model {mid}: its {type(value).__name__} ({attr}) reads "
                              f"{name_of(old)} = {name_of(new)} of the previous step, but "
                              f"old_state does not copy it: add ({name_of(new)!r}, "
                              f"{name_of(old)!r}) to old_state"))
    # what a step reads from the previous one is in the checkpoint
    saved = checkpoint_functions(model)
    if saved:
        ids = {id(f) for f in saved.values()}
        for name, new, _ in pairs:
            if id(new) not in ids:
                found.append(("checkpoint",
                              f"model {mid}: the step starts from {name!r} of the previous step "
                              f"(old_state) but its checkpoint ({', '.join(saved) or 'nothing'}) "
                              f"does not hold it: a restart would start from a wrong {name!r}; "
                              "add it to checkpoint_fields or to what checkpoint_state() returns"))
    # the declared prefix of each sub-step is its solver's
    for step in model.scheme():
        if step.solve is None:
            continue
        used = _solver_prefix(step.solve)
        if used is not None and used != step.prefix:
            found.append(("prefixes",
                          f"model {mid}: sub-step {step.name!r} declares the PETSc prefix "
                          f"{step.prefix!r}, but its solver uses {used!r} (-{step.prefix}... "
                          f"options would not reach it): declare prefix={used!r}"))
    # the mesh-dependent stability limit, where the model gives it
    if model.dynamic and type(model).mesh_k_max is not _base_mesh_k_max():
        try:
            mesh_k_max(model)
        except ContractError as exc:
            found.append(("stability_limit", str(exc)))
    return found


def _base_mesh_k_max():
    from damage_dolfinx.models.base import Model
    return Model.mesh_k_max


def mesh_k_max(model) -> float:
    """The built model's mesh-dependent stability limit (:meth:`Model.mesh_k_max`), checked:
    a positive number or inf (None from the model: no limit)."""
    try:
        value = model.mesh_k_max()
    except NotImplementedError as exc:
        raise ContractError(str(exc)) from None
    if value is None:
        return math.inf
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
        raise ContractError(f"model {model.id}: mesh_k_max() returned {value!r}, not a positive "
                            "number (None: no limit)")
    return float(value)
