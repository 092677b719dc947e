"""What a run is given, resolved to the Problem to run: a
:class:`~damage_dolfinx.Problem` (checked: ``problem.checked()``; a catalogue example is one),
or a name that a registered source
knows (the thesis catalogue registers its ids when ``damage_dolfinx.catalogue`` is imported;
the run machinery does not import it)."""
from __future__ import annotations

from damage_dolfinx.core.parameters import InputError

_SOURCES: list = []


def register(lookup):
    """Add a source of named cases: ``lookup(name, reading) -> description`` raising
    InputError for a name it does not know."""
    if lookup not in _SOURCES:
        _SOURCES.append(lookup)


def resolve(case, overrides=None):
    """A registered name or a Problem -> the checked Problem to run."""
    if isinstance(case, str):
        if not _SOURCES:
            raise InputError(f"unknown case {case!r}: no catalogue is loaded (import "
                             "damage_dolfinx.catalogue, or give a Problem)")
        return _SOURCES[-1](case, (overrides or {}).get("reading"))
    if hasattr(case, "checked"):
        return case.checked()
    raise InputError(f"a run is a Problem or a case name, got {type(case).__name__}")
