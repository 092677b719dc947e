"""A run folder read back into a script: ``read_run(folder)``.

    run = dd.read_run("results/my-run")
    run.summary["status"], run.summary["final"]["zeta_min"]     # summary.json
    run.history["t"], run.history["zeta_min"]                    # history.csv, one array a column
    run.times                                                    # the stored times of fields.xdmf
    f = run.field("zeta", t=0.5)                                 # f.t, f.coords, f.values
    run.integral("v", t=0.5)                                     # int_Omega v dx (per component)
    run.final["zeta"]                                            # fields_final.npz

Read-back never lies: a time outside the stored range (or NaN, an infinity, a non-number) is
refused with the range in the message, and a damaged or partial file (cut short, bad XML, JSON,
CSV or NPZ) gives one InputError naming the file. Reading never disturbs a run writing the folder:
HDF5 files are opened without file locking.

Fields come in the rank-independent order of ``fields_final.npz`` (nodes, or cell midpoints for
cell fields, sorted by x, then y (then z)), so a run made on any number of ranks, restarted or
not, reads back the same arrays. Reading fields needs h5py (installed by ``make setup``).
"""
from __future__ import annotations

import csv
import json
import os
import zipfile
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
        try:
            self.summary = json.loads(path.read_text(encoding="utf-8"))
        except (ValueError, UnicodeDecodeError) as exc:  # JSONDecodeError is a ValueError
            raise InputError(f"cannot read {str(path)!r}: not valid JSON ({exc}): the file is "
                             "damaged or was cut short") from None
        except OSError as exc:
            raise InputError(f"cannot read {str(path)!r}: {exc.strerror or exc}") from None
        if not isinstance(self.summary, dict):
            raise InputError(f"cannot read {str(path)!r}: not a run summary (a JSON "
                             f"{type(self.summary).__name__}, not an object)")
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
        """Field ``name`` at the stored time nearest ``t`` (default: the last one). A time
        outside the stored range, NaN, an infinity or a non-number is refused (InputError,
        naming the range); a damaged file gives an InputError naming it."""
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
        try:
            with np.load(path) as data:
                return dict(data)
        except (OSError, ValueError, EOFError, zipfile.BadZipFile, KeyError) as exc:
            reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            raise InputError(f"cannot read {str(path)!r}: {reason}: the file is damaged or "
                             "was cut short") from None


def _history(path) -> dict:
    """history.csv as column -> float array (NaN where a row has no value)."""
    if not path.is_file():
        return {}
    try:
        with open(path, newline="", encoding="utf-8") as f:
            rows = list(csv.DictReader(f))
    except (csv.Error, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read {str(path)!r}: not a CSV table ({exc}): the file is "
                         "damaged") from None
    except OSError as exc:
        raise InputError(f"cannot read {str(path)!r}: {exc.strerror or exc}") from None
    if not rows:
        return {}
    header = [c for c in rows[0] if c is not None]
    if "t" not in header:
        raise InputError(f"cannot read {str(path)!r}: no column 't' in its header (columns: "
                         f"{', '.join(map(str, header[:8]))}): not a run's history")

    def number(text):
        try:
            return float(text)
        except (TypeError, ValueError):
            return np.nan
    return {c: np.array([number(r.get(c)) for r in rows]) for c in header}


def read_run(folder: "Union[str, os.PathLike[str]]") -> RunResults:
    """Read the run folder ``folder`` (made by ``run`` or the command line, on any number of
    ranks, restarted or not): its summary, its history as arrays and its stored fields at any
    output time (``RunResults``). Raises InputError when the folder holds no run."""
    return RunResults(folder)
