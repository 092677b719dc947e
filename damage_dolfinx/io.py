"""Output of a run: XDMF time series, CSV history, JSON metadata, gathered final fields.

Everything is written incrementally: the XDMF file is re-opened in append mode for each output
time and the CSV row is flushed after each step, so an interrupted run keeps every finished step.
Only rank 0 writes CSV/JSON/NPZ; XDMF is collective.
"""
from __future__ import annotations

import csv
import json
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from . import compat
from .parameters import InputError


def prepare_output_dir(path, comm=MPI.COMM_WORLD) -> Path:
    """Create ``path`` and check it is writable, before any computation; raises InputError."""
    path = Path(path)
    error = None
    if comm.rank == 0:
        try:
            path.mkdir(parents=True, exist_ok=True)
            probe = path / ".write_test"
            probe.write_text("ok")
            probe.unlink()
        except OSError as exc:
            error = f"output folder {str(path)!r} is not writable: {exc.strerror or exc}"
    error = comm.bcast(error, root=0)
    if error:
        raise InputError(error)
    return path


def write_json(path, data, comm=MPI.COMM_WORLD):
    """Atomically write ``data`` as JSON (rank 0)."""
    if comm.rank != 0:
        return
    path = Path(path)
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(json.dumps(data, indent=2, sort_keys=False, default=_json_default) + "\n")
    os.replace(tmp, path)


def _json_default(obj):
    if isinstance(obj, (np.floating, np.integer)):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    return str(obj)


def environment(comm=MPI.COMM_WORLD) -> dict:
    """Versions and machine facts for the run metadata."""
    import petsc4py
    import ufl
    from petsc4py import PETSc
    from . import __version__
    return {"damage_dolfinx": __version__, "dolfinx": compat.DOLFINX_VERSION,
            "ufl": ufl.__version__, "petsc": ".".join(map(str, PETSc.Sys.getVersion())),
            "petsc4py": petsc4py.__version__, "python": platform.python_version(),
            "mpi_size": comm.size, "host": platform.node(),
            "command": " ".join(sys.argv), "date": time.strftime("%Y-%m-%dT%H:%M:%S%z")}


class CSVHistory:
    """One CSV row per time step, flushed immediately (rank 0)."""

    def __init__(self, path, columns, comm=MPI.COMM_WORLD, keep_until_step=None):
        """A new file, or with ``keep_until_step`` (restart) the existing rows of steps up to
        that one followed by the new rows."""
        self.columns, self.comm = list(columns), comm
        self._file = None
        if comm.rank == 0:
            kept = []
            if keep_until_step is not None and Path(path).is_file():
                with open(path, newline="") as f:
                    kept = [r for r in csv.DictReader(f) if int(r["step"]) <= keep_until_step]
            self._file = open(path, "w", newline="")
            self._writer = csv.DictWriter(self._file, fieldnames=self.columns)
            self._writer.writeheader()
            for row in kept:
                self._writer.writerow({c: row.get(c, "") for c in self.columns})
            self._file.flush()

    def write(self, row: dict):
        if self._file is not None:
            self._writer.writerow({c: row.get(c, "") for c in self.columns})
            self._file.flush()

    def close(self):
        if self._file is not None:
            self._file.close()
            self._file = None


class XDMFSeries:
    """XDMF/HDF5 time series of several fields on one mesh, for ParaView."""

    def __init__(self, path, msh):
        self.path, self.comm = Path(path), msh.comm
        with compat.xdmf_file(self.comm, self.path, "w") as f:
            f.write_mesh(msh)

    def write(self, functions, t: float):
        with compat.xdmf_file(self.comm, self.path, "a") as f:
            for fn in functions:
                f.write_function(fn, t)


def gather_dof_field(u):
    """On rank 0: (coords (N,2), values (N, bs)) of all owned dofs of a P1 or DG0 Function, in a
    rank-independent order (sorted by coordinates); None elsewhere."""
    V = u.function_space
    n_owned = V.dofmap.index_map.size_local
    bs = V.dofmap.index_map_bs
    coords = V.tabulate_dof_coordinates()[:n_owned, :2]
    values = u.x.array.reshape(-1, bs)[:n_owned]
    all_coords = V.mesh.comm.gather(coords, root=0)
    all_values = V.mesh.comm.gather(values, root=0)
    if V.mesh.comm.rank != 0:
        return None
    coords = np.concatenate(all_coords)
    values = np.concatenate(all_values)
    key = np.round(coords, 10)
    order = np.lexsort((key[:, 1], key[:, 0]))
    return coords[order], values[order]


def save_final_fields(path, functions: dict):
    """Write the gathered final fields (name -> Function) to one NPZ (rank 0)."""
    data = {}
    for name, fn in functions.items():
        gathered = gather_dof_field(fn)
        if gathered is not None:
            data[name + "_coords"], data[name] = gathered
    if data:
        np.savez(path, **data)
