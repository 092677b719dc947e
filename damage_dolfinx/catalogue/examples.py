"""Catalogue of the thesis examples by id (``2.1-ex1`` ...): data, geometry, scheme, defaults.

Every value the thesis leaves open is an explicit assumption, listed in the example's
``assumptions`` and copied into each run's summary.json, its short label written out as
"assumed" (:func:`damage_dolfinx.problem.example.in_words`); docs/models.md gives the reasons,
model by model. An example is a run description (:mod:`damage_dolfinx.problem.example`) with the thesis's
metadata; this module only collects them by id.
"""
from __future__ import annotations

from damage_dolfinx.problem.example import (MAX_STEPS, READINGS, Example, Figure,  # noqa: F401
                                        Reading)
from damage_dolfinx.core.parameters import InputError


#: catalogue modules (damage_dolfinx/catalogue/<name>.py), each with examples() -> [Example]
SECTIONS = ["section_2_1", "section_2_2", "section_2_3", "bridge", "section_2_4", "section_3_1",
            "section_3_2", "section_3_3", "section_3d", "section_3d_tresca"]


def catalogue(reading=None) -> dict:
    """All examples by id, in section order, under ``reading`` (None: each one's default)."""
    import importlib
    out = {}
    for name in SECTIONS:
        module = importlib.import_module(f"{__package__}.{name}")
        out.update({ex.id: ex.with_reading(reading) for ex in module.examples()})
    return out


def get(example_id: str, reading=None) -> Example:
    """The example under ``reading`` (None: its default reading)."""
    if reading is not None and reading not in READINGS:
        raise InputError(f"unknown reading {reading!r}; known: {', '.join(READINGS)}")
    examples = catalogue(reading)
    if example_id not in examples:
        from damage_dolfinx.runtime.cases import UnknownCase  # (the next source is tried)
        raise UnknownCase(f"unknown example id {example_id!r}; known ids: {', '.join(examples)} "
                         f"(see `damage-dolfinx list`)")
    return examples[example_id]
