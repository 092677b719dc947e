"""Writes that fail cleanly: files written to a temporary file and renamed into
place (a kill never leaves a truncated file, a failed write gives its space back), and I/O
errors turned into one line, OutputError, raised on every rank (``collective``), so ranks never
wait for each other and the command line exits with status 4.
"""
from __future__ import annotations

import errno
import io as _io
import json
import os
import shutil
import sys
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI


from damage_dolfinx.core.errors import OutputError  # noqa: F401


def describe(exc: BaseException, folder=None) -> str:
    """One line for an I/O exception (HDF5 reports a full disk only as 'Failed to close ...')."""
    text = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc).splitlines()[0]
    text = text.rstrip(".")  # HDF5's messages end with a full stop
    if folder is not None and not (isinstance(exc, OSError) and exc.errno == errno.ENOSPC):
        try:
            if shutil.disk_usage(folder).free < 1 << 16:
                text += " (the disk is full)"
        except OSError:
            text += " (the output folder is gone)"
    return text


#: a rank whose write failed waits this long for the others, then aborts the job: a rank can
#: be stuck for ever inside a collective HDF5 call that the failed rank left
STUCK_SECONDS = 60.0


def collective(comm, folder, what: str, fn, *args):
    """Run the write ``fn(*args)`` on every rank; an OSError/RuntimeError on any rank raises
    OutputError("cannot write WHAT: reason") on every rank (``what`` names file, step and time)."""
    error = None
    try:
        fn(*args)
    except (OSError, RuntimeError) as exc:
        error = describe(exc, folder)
    if comm.size > 1:
        failed = np.zeros(comm.size, np.int32)
        request = comm.Iallgather(np.array([error is not None], np.int32), failed)
        deadline = time.monotonic() + STUCK_SECONDS
        while not request.Test():
            if error is not None and time.monotonic() > deadline:
                print(f"damage-dolfinx: output error: cannot write {what}: {error} (another "
                      "rank is stuck in the collective write: job aborted)", file=sys.stderr,
                      flush=True)
                comm.Abort(4)
            time.sleep(0.001)
        if failed.any():
            error = comm.bcast(error, root=int(np.flatnonzero(failed)[0]))
    if error:
        raise OutputError(f"cannot write {what}: {error}")


def atomic_write_bytes(path, write, fsync=False):
    """Write a file through ``write(fileobj)`` into ``path.tmp`` and rename it onto ``path``;
    the temporary file is removed if anything fails (so a full disk gets its space back)."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    try:
        with open(tmp, "wb") as f:
            write(f)
            f.flush()
            if fsync:
                os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            tmp.unlink()
        except OSError:
            pass
        raise


def write_json(path, data, comm=MPI.COMM_WORLD):
    """Atomically write ``data`` as strict JSON (rank 0; raises OSError there): see
    ``strict_json``."""
    if comm.rank != 0:
        return
    text = strict_json(data)
    atomic_write_bytes(path, lambda f: f.write(text.encode()))


def strict_json(data, indent=2) -> str:
    """``data`` as JSON that every reader accepts: a NaN or an infinity (which Python's json
    would write as the bare words NaN / Infinity) becomes null, and a top-level dict gains
    ``null_values``: {"key.path": "NaN" | "Infinity" | "-Infinity"} saying what it was."""
    reasons = {}
    clean = _finite(data, "", reasons)
    if reasons and isinstance(clean, dict):
        clean["null_values"] = {**(clean.get("null_values") or {}), **reasons}
    return json.dumps(clean, indent=indent, sort_keys=False, default=_json_default,
                      allow_nan=False) + "\n"


def _finite(value, where, reasons):
    if isinstance(value, (np.floating, np.integer, np.bool_)):
        value = value.item()
    elif isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, float):
        if value != value or value in (float("inf"), float("-inf")):
            reasons[where.lstrip(".") or "value"] = ("NaN" if value != value else
                                                    "Infinity" if value > 0 else "-Infinity")
            return None
        return value
    if isinstance(value, dict):
        return {k: _finite(v, f"{where}.{k}", reasons) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(v, f"{where}[{i}]", reasons) for i, v in enumerate(value)]
    return value


def _json_default(obj):
    if isinstance(obj, (np.floating, np.integer)):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    return str(obj)


def npz_writer(arrays: dict):
    """A ``write(fileobj)`` for atomic_write_bytes: the NPZ is built in memory, so a failed
    write leaves no half-closed zip object behind (no 'Exception ignored' noise)."""
    def write(f):
        buffer = _io.BytesIO()
        np.savez(buffer, **arrays)
        f.write(buffer.getbuffer())
    return write
