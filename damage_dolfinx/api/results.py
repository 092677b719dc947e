"""A run folder read back into a script: ``read_run(folder)``.

    run = dd.read_run("results/my-run")
    run.summary["status"], run.summary["final"]["zeta_min"]     # summary.json
    run.history["t"], run.history["zeta_min"]                    # history.csv, one array a column
    run.times                                                    # the stored times of fields.xdmf
    f = run.field("zeta", t=0.5)                                 # f.t, f.coords, f.values
    run.integral("v", t=0.5)                                     # int_Omega v dx (per component)
    run.final["zeta"]                                            # fields_final.npz

Fields come in the rank-independent order of ``fields_final.npz`` (nodes, or cell midpoints for
cell fields, sorted by x, then y (then z)), so a run made on any number of ranks, restarted or
not, reads back the same arrays. Reading fields needs h5py (installed by ``make setup``).
"""
from __future__ import annotations

import csv
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Union

import numpy as np

from damage_dolfinx.core.parameters import InputError


@dataclass(frozen=True)
class Field:
    """One stored field at one time: ``values`` (N, components) at ``coords`` (N, dim)."""
    name: str
    t: float
    coords: np.ndarray
    values: np.ndarray


class RunResults:
    """What a run folder holds: ``summary`` (dict), ``history`` (column -> array), ``times``
    and ``names`` of the stored fields, ``field(name, t)``, ``final`` (fields_final.npz)."""

    def __init__(self, folder):
        self.folder = Path(folder)
        path = self.folder / "summary.json"
        if not path.is_file():
            raise InputError(f"{str(self.folder)!r} holds no run (no summary.json)")
        self.summary = json.loads(path.read_text())
        self.history = _history(self.folder / "history.csv")
        self._series = None

    @property
    def series(self):
        if self._series is None:
            from damage_dolfinx.runtime.series import Series
            name = self.summary.get("outputs", {}).get("xdmf", "fields.xdmf")
            if not (self.folder / name).is_file():
                raise InputError(f"{str(self.folder)!r} holds no {name}")
            self._series = Series(self.folder / name)
        return self._series

    @property
    def times(self) -> np.ndarray:
        """The stored output times, increasing, each once."""
        return np.array(self.series.times)

    @property
    def names(self) -> list:
        return list(self.series.names)

    def field(self, name: str, t: float = None) -> Field:
        """Field ``name`` at the stored time nearest ``t`` (default: the last one)."""
        coords, values, t_found = self.series.field(name, t)
        return Field(name, t_found, coords, values)

    def integral(self, name: str, t: float = None) -> np.ndarray:
        """int_Omega of field ``name`` at the stored time nearest ``t`` (default: the last),
        one value per component (exact for P1 and cell fields on triangles and tetrahedra)."""
        return self.series.integral(name, t)

    @property
    def final(self) -> dict:
        """fields_final.npz: ``name`` and ``name_coords`` arrays ({} when absent)."""
        path = self.folder / "fields_final.npz"
        if not path.is_file():
            return {}
        with np.load(path) as data:
            return dict(data)


def _history(path) -> dict:
    """history.csv as column -> float array (NaN where a row has no value)."""
    if not path.is_file():
        return {}
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        return {}

    def number(text):
        try:
            return float(text)
        except (TypeError, ValueError):
            return np.nan
    return {c: np.array([number(r.get(c)) for r in rows]) for c in rows[0]}


def read_run(folder: "Union[str, os.PathLike[str]]") -> RunResults:
    """Read the run folder ``folder`` (made by ``run`` or the command line, on any number of
    ranks, restarted or not): its summary, its history as arrays and its stored fields at any
    output time (``RunResults``). Raises InputError when the folder holds no run."""
    return RunResults(folder)
