"""Output of a run: XDMF time series, CSV history, JSON metadata, gathered final fields.

Everything is written incrementally: the XDMF file is re-opened in append mode for each output
time and the CSV row is flushed after each step, so an interrupted run keeps every finished step.
Only rank 0 writes CSV/JSON/NPZ; XDMF is collective. JSON and NPZ files are written to a temporary
file and renamed (atomic.py: a kill never leaves a truncated file); the history is appended row by
row (a full disk can truncate at most its last row, which a restart drops). A write that fails on
any rank raises OutputError on every rank (``atomic.collective``), so ranks never wait for each
other. The run folder and its lock: runfolder.py.
"""
from __future__ import annotations

import contextlib
import csv
import ctypes
import errno
import io as _io
import os
import platform
import shutil
import sys
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from damage_dolfinx import compat
from damage_dolfinx.runtime import series
from damage_dolfinx.runtime.atomic import (STUCK_SECONDS, OutputError, atomic_write_bytes, collective,  # noqa: F401
                     describe, npz_writer, strict_json, write_json)
from damage_dolfinx.core.parameters import InputError


def prepare_output_dir(path, comm=MPI.COMM_WORLD) -> Path:
    """Create ``path`` and check it is writable, before any computation; raises InputError."""
    path = Path(path)
    error = None
    if comm.rank == 0:
        try:
            if path.is_symlink() and not path.exists():
                raise OSError(0, "it is a symbolic link to nothing (dangling, or a loop of links)")
            if path.exists() and not path.is_dir():
                raise OSError(0, "it is a file, not a folder")
            if not path.exists():
                from damage_dolfinx.runtime.collective import created
                created(path)  # removed again if the call is refused while it is empty
            path.mkdir(parents=True, exist_ok=True)
            probe = path / f".damage-dolfinx-write-test-{os.getpid()}"  # never a user's file
            os.close(os.open(probe, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600))
            probe.unlink()
        except OSError as exc:
            error = f"output folder {str(path)!r} is not writable: {exc.strerror or exc}"
    error = comm.bcast(error, root=0)
    if error:
        raise InputError(error)
    return path


def environment(comm=MPI.COMM_WORLD) -> dict:
    """Versions and machine facts for the run metadata."""
    import petsc4py
    import ufl
    from petsc4py import PETSc
    from damage_dolfinx.core.version import __version__
    return {"damage_dolfinx": __version__, "dolfinx": compat.DOLFINX_VERSION,
            "ufl": ufl.__version__, "petsc": ".".join(map(str, PETSc.Sys.getVersion())),
            "petsc4py": petsc4py.__version__, "python": platform.python_version(),
            "mpi_size": comm.size, "host": platform.node(),
            "command": " ".join(sys.argv), "date": time.strftime("%Y-%m-%dT%H:%M:%S%z")}


class CSVHistory:
    """One CSV row per time step, appended and flushed immediately (rank 0). A failed write is
    kept in ``error`` (the runner checks it collectively at the end of the step) instead of
    raising on rank 0 alone."""

    def __init__(self, path, columns, comm=MPI.COMM_WORLD, keep_until_step=None):
        """A new file, or with ``keep_until_step`` (restart) the existing complete rows of steps
        up to that one followed by the new rows; the file is replaced atomically, then appended.
        Raises OSError (rank 0)."""
        self.columns, self.comm, self.path = list(columns), comm, Path(path)
        self._file, self.error = None, None
        if comm.rank == 0:
            kept = self.read_rows(path, keep_until_step) if keep_until_step is not None else []

            def write(f):
                text = _io.TextIOWrapper(f, newline="", encoding="utf-8")
                writer = csv.DictWriter(text, fieldnames=self.columns)
                writer.writeheader()
                for row in kept:
                    writer.writerow({c: row.get(c, "") for c in self.columns})
                text.flush()
                text.detach()
            atomic_write_bytes(path, write)
            self._file = open(path, "a", newline="")
            self._writer = csv.DictWriter(self._file, fieldnames=self.columns)

    @staticmethod
    def read_rows(path, until_step) -> list:
        """Complete rows (all columns, ending in a newline) of steps <= until_step."""
        if not Path(path).is_file():
            return []
        text = Path(path).read_text()
        if text and not text.endswith("\n"):  # a row cut by a full disk
            text = text[:text.rfind("\n") + 1]
        rows = csv.DictReader(text.splitlines())
        return [r for r in rows if None not in r.values() and None not in r
                and r["step"].isdigit() and int(r["step"]) <= until_step]

    def write(self, row: dict):
        if self._file is not None and self.error is None:
            try:
                self._writer.writerow({c: row.get(c, "") for c in self.columns})
                self._file.flush()
            except OSError as exc:
                self.error = exc

    def close(self):
        if self._file is not None:
            try:
                self._file.close()
            except OSError:
                pass  # a full disk: the rows that were flushed stay
            self._file = None


class XDMFSeries:
    """The run's time series of several fields on one mesh (series_file.py: one grid per output
    time with every field, the nodes in a rank-independent order, for ParaView, meshio and
    ``read_run``). A failed write (full disk) raises OSError with one line on rank 0, which
    ``atomic.collective`` turns into an OutputError on every rank."""

    def __init__(self, path, msh, index=None, since=None):
        """A new series at ``path`` (its data in ``path`` with .h5); with ``index`` (a
        restart's segment) the run's index file, whose time grids t <= ``since`` are kept before
        this segment's (series.py). Collective."""
        from damage_dolfinx.runtime.series_file import SeriesWriter
        self.path, self.comm = Path(path), msh.comm
        self.index = Path(index) if index else self.path
        earlier = []
        if self.index != self.path and self.comm.rank == 0 and since is not None:
            earlier = series.earlier_grids(self.index, since)
        self._earlier = earlier
        with _stderr_held_back():
            self.writer = SeriesWriter(msh, self.path.with_suffix(".h5"), self.index, earlier)

    @property
    def segments(self) -> list:
        """The .h5 files the run's series references (rank 0; [] elsewhere)."""
        if self.comm.rank != 0:
            return []
        names = series.data_files(self._earlier)
        return names + [n for n in [self.path.stem + ".h5"] if n not in names]

    def write(self, functions, t: float):
        """Append the fields at ``t`` (collective); the index XML is replaced atomically after
        the data is on disk, so it never names data that is not there."""
        error = None
        if self.comm.rank == 0:
            need = 65536 + 2 * sum(fn.function_space.dofmap.index_map.size_global * 8 * (
                fn.function_space.dofmap.index_map_bs) + 4096 for fn in functions)
            try:  # refused before any rank enters the gather
                free = shutil.disk_usage(self.path.parent).free
                if free < need:
                    raise OSError(errno.ENOSPC, f"No space left on device ({free // 1024} kB "
                                                f"free, the output needs ~{need // 1024} kB)")
            except OSError as exc:
                error = exc
        error = self.comm.bcast(error, root=0)
        if error:
            raise error
        try:
            with _stderr_held_back():  # HDF5's error stack: shown only if the write succeeds
                self.writer.write(functions, t, lambda path, xml: atomic_write_bytes(
                    path, lambda f: f.write(xml)))
        except (ValueError, KeyError, TypeError) as exc:  # h5py's own, on rank 0
            raise OSError(f"{self.path.with_suffix('.h5').name}: {exc}") from None


def series_outputs(xdmf) -> dict:
    """The summary.json outputs entries of the run's time series (collective)."""
    segments = xdmf.comm.bcast(xdmf.segments, root=0)
    return {"xdmf": "fields.xdmf", "xdmf_data": segments, "xdmf_series": series.MECHANISM}


def repair_xdmf(out) -> list:
    """Put back the XML of every XDMF file in ``out`` whose write was killed (it does not
    parse and its ``.bak`` does); returns the names repaired (rank 0)."""
    repaired = []
    for backup in sorted(Path(out).glob("*.xdmf.bak")):
        path = backup.with_name(backup.name[:-4])
        try:
            if not _parses(path) and _parses(backup):
                os.replace(backup, path)
                repaired.append(path.name)
            else:
                backup.unlink()  # the write had finished (or the copy is no better)
        except OSError:
            pass  # left as it is: the restart itself does not need it
    return repaired


def _parses(path) -> bool:
    import xml.etree.ElementTree as ET
    try:
        ET.parse(path)
        return True
    except (ET.ParseError, OSError):
        return False


#: HDF5 files whose write or close failed, kept alive (series_file.py, the same list)
from damage_dolfinx.runtime.series_file import FAILED_HDF5_FILES  # noqa: E402


@contextlib.contextmanager
def _failed_files_kept(f):
    try:
        yield
    except RuntimeError:
        FAILED_HDF5_FILES.append(f)
        ctypes.pythonapi.Py_IncRef(ctypes.py_object(f))  # never destroyed: no second close
        raise


@contextlib.contextmanager
def _stderr_held_back():
    """File descriptor 2 goes to a memory file; replayed unless an exception is raised."""
    sys.stderr.flush()
    saved, memory = os.dup(2), os.memfd_create("held-back-stderr")
    os.dup2(memory, 2)
    failed = True
    try:
        yield
        failed = False
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        if not failed and os.lseek(memory, 0, os.SEEK_END):
            os.lseek(memory, 0, os.SEEK_SET)
            sys.stderr.write(os.read(memory, 1 << 20).decode(errors="replace"))
        os.close(memory)


def gather_dof_field(u):
    """On rank 0: (coords (N,2), values (N, bs)) of all owned dofs of a P1 or DG0 Function, in a
    rank-independent order (sorted by coordinates); None elsewhere."""
    V = u.function_space
    n_owned = V.dofmap.index_map.size_local
    bs = V.dofmap.index_map_bs
    coords = V.tabulate_dof_coordinates()[:n_owned, :V.mesh.topology.dim]  # (N,2), 3-D: (N,3)
    values = u.x.array.reshape(-1, bs)[:n_owned]
    all_coords = V.mesh.comm.gather(coords, root=0)
    all_values = V.mesh.comm.gather(values, root=0)
    if V.mesh.comm.rank != 0:
        return None
    coords = np.concatenate(all_coords)
    values = np.concatenate(all_values)
    key = np.round(coords, 10)
    order = np.lexsort(key.T[::-1])  # by x, then y (then z)
    return coords[order], values[order]


def save_final_fields(path, functions: dict):
    """Write the gathered final fields (name -> Function) to one NPZ (rank 0)."""
    data = {}
    for name, fn in functions.items():
        gathered = gather_dof_field(fn)
        if gathered is not None:
            data[name + "_coords"], data[name] = gathered
    if data:
        atomic_write_bytes(path, npz_writer(data))
