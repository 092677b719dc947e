"""What a run is given, resolved to the Problem to run: a
:class:`~damage_dolfinx.Problem` (checked: ``problem.checked()``; a catalogue example is one),
or a name that a registered source knows. The sources, tried in this order:

* the sources registered with :func:`register` (the thesis catalogue registers its ids when
  ``damage_dolfinx.catalogue`` is imported; the run machinery does not import it);
* the examples registered with :func:`register_example` (``damage_dolfinx.register_example``,
  e.g. by a plugin of the command line);
* the id of a registered model whose class has an ``example()`` classmethod returning its
  example Problem (the model's defaults on a mesh of its own).

A source raises :class:`UnknownCase` (an InputError) for a name it does not know."""
from __future__ import annotations

from damage_dolfinx.core.parameters import InputError

_SOURCES: list = []
#: id -> Problem, registered by register_example
_EXAMPLES: dict = {}


class UnknownCase(InputError):
    """A case name no source knows (the next source is tried)."""


def register(lookup):
    """Add a source of named cases: ``lookup(name, reading) -> description`` raising
    UnknownCase (an InputError) for a name it does not know."""
    if lookup not in _SOURCES:
        _SOURCES.append(lookup)


def register_example(problem, id=None):
    """Make ``problem`` (a :class:`~damage_dolfinx.Problem`) runnable by its id (``id``, else
    ``problem.name``): ``damage-dolfinx run ID`` (with a plugin that registers it),
    ``converge ID``, ``sweep ID``, ``show ID``, and ``dd.run("ID", ...)``. Returns the
    problem. An id taken by another registered example is refused."""
    if not hasattr(problem, "checked") or not hasattr(problem, "model"):
        raise InputError(f"register_example: a Problem, got {type(problem).__name__}")
    name = problem.name if id is None else id
    if not isinstance(name, str) or not name or name == "problem":
        raise InputError("register_example: give the example an id (Problem(name=...) or id=)")
    if _EXAMPLES.get(name, problem) is not problem:
        raise InputError(f"register_example: example id {name!r} is taken")
    _EXAMPLES[name] = problem
    return problem


def registered() -> dict:
    """id -> title of the examples and model examples registered beyond the sources."""
    out = {name: getattr(p, "title", "") or f"model {p.model_id}" for name, p in _EXAMPLES.items()}
    for name, cls in _model_examples().items():
        out.setdefault(name, cls.title)
    return out


def _model_examples() -> dict:
    """id -> class of the registered models with an ``example()`` (the package's own models
    have none: their examples are the catalogue's)."""
    import sys
    if "damage_dolfinx.models.registry" not in sys.modules:  # no model of one's own registered
        return {}
    from damage_dolfinx.models import registry
    return {key: cls for key, cls in registry._registered.items()
            if callable(getattr(cls, "example", None))}


def _model_hint(name) -> str:
    """The message for a model id given where an example id is expected ("" when ``name`` is no
    model id): the package's models run through their catalogue examples, a model of one's own
    through the Problem its ``example()`` classmethod returns."""
    from damage_dolfinx.models import registry
    cls = registry.MODELS.get(name)
    if cls is None:
        return ""
    if cls.__module__.startswith("damage_dolfinx."):
        return (f"{name!r} is a model id, not an example id: the command line runs examples "
                f"(`damage-dolfinx list`); a script runs a Problem with model={name!r}")
    return (f"{name!r} is a registered model without an example: give {cls.__name__} a "
            "classmethod example() that returns its Problem (docs: Writing a model, "
            "'Running it'), or run a Problem of it from a script")


def _own(name, reading):
    problem = _EXAMPLES.get(name)
    if problem is None:
        cls = _model_examples().get(name)
        if cls is None:
            raise UnknownCase(f"unknown example id {name!r}")
        problem = cls.example()
        if not hasattr(problem, "checked"):
            raise InputError(f"model {name!r}: example() must return a Problem, got "
                             f"{type(problem).__name__}")
    if reading is not None and reading != getattr(problem, "reading", None):
        problem = problem.with_reading(reading)
    return problem.checked()


def resolve(case, overrides=None):
    """A registered name or a Problem -> the checked Problem to run."""
    if isinstance(case, str):
        reading = (overrides or {}).get("reading")
        first = None
        for lookup in list(reversed(_SOURCES)) + [_own]:
            try:
                return lookup(case, reading)
            except UnknownCase as exc:
                first = first or exc
        own = registered()
        if not _SOURCES and not own:
            raise InputError(f"unknown case {case!r}: no catalogue is loaded (import "
                             "damage_dolfinx.catalogue, or give a Problem)")
        hint = _model_hint(case)
        if hint:
            raise UnknownCase(hint)
        extra = f"; registered: {', '.join(own)}" if own else ""
        raise UnknownCase(f"{first}{extra}")
    if hasattr(case, "checked"):
        return case.checked()
    raise InputError(f"a run is a Problem or a case name, got {type(case).__name__}")
