"""The run folder: its lock (a second run into a folder where one is live is refused;
a dead run's lock, even after SIGKILL, never blocks), the run it already holds, and removing
that run's files (--overwrite)."""
from __future__ import annotations

import fcntl
import json
import os
import socket
import time
from pathlib import Path

from mpi4py import MPI

from damage_dolfinx.runtime import checkpoint
from damage_dolfinx.parameters import InputError

#: files of a run that --overwrite removes (figures are overwritten by the new run)
RUN_FILES = ("summary.json", "history.csv", "fields_final.npz", "checkpoint.json",
             *checkpoint.GENERATIONS)


class RunLock:
    """``out/.lock``, held (flock) by rank 0 of the live run; the kernel drops it when that
    process dies, even by SIGKILL, so a dead run never blocks a new one. Raises InputError when
    a live run holds it. Where the file system has no flock, a lock whose process is gone (same
    host) is taken over. The file also reserves RESERVE bytes of disk that ``free_reserve``
    gives back, so that a run stopped by a full disk can still record it in summary.json."""

    RESERVE = 1 << 16

    def __init__(self, out, comm=MPI.COMM_WORLD):
        self.path, self.comm, self._fd = Path(out) / ".lock", comm, None
        try:
            error = self._acquire() if comm.rank == 0 else None
        except OSError as exc:  # e.g. the folder removed since prepare_output_dir
            error = f"cannot lock {str(self.path)!r}: {exc.strerror or exc}"
        error = comm.bcast(error, root=0)
        if error:
            raise InputError(error)

    def _acquire(self):
        for _ in range(10):  # the file may be replaced between open and flock (see release)
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                holder = os.read(fd, 1000).decode(errors="replace").split("\n")[0]
                os.close(fd)
                return f"a run is live in {str(self.path.parent)!r} ({holder or 'see .lock'}); " \
                       f"wait for it to end or stop it (a dead run's lock is released at once)"
            except OSError:  # no flock on this file system: the recorded process must be gone
                holder = os.read(fd, 1000).decode(errors="replace").split()
                if len(holder) >= 4 and _alive(holder[1], holder[3]):
                    os.close(fd)
                    return f"a run is live in {str(self.path.parent)!r} (pid {holder[1]})"
            try:
                same = os.fstat(fd).st_ino == os.stat(self.path).st_ino
            except FileNotFoundError:
                same = False
            if same:
                os.ftruncate(fd, 0)
                self._header = (f"pid {os.getpid()} host {socket.gethostname()} since "
                                f"{time.strftime('%Y-%m-%dT%H:%M:%S')}\n").encode()
                try:
                    os.pwrite(fd, self._header + b" " * self.RESERVE, 0)
                except OSError:  # a nearly full disk: no reserve
                    os.ftruncate(fd, 0)
                    os.pwrite(fd, self._header, 0)
                self._fd = fd
                return None
            os.close(fd)
        return f"cannot lock {self.path}"

    def free_reserve(self):
        if self._fd is not None:
            os.ftruncate(self._fd, len(self._header))

    def release(self):
        if self._fd is not None:
            try:
                self.path.unlink()  # before unlocking: a waiting opener then retries
            except OSError:
                pass
            os.close(self._fd)
            self._fd = None


def _alive(pid, host) -> bool:
    if host != socket.gethostname():
        return True  # cannot tell: assume live
    try:
        os.kill(int(pid), 0)
    except (ProcessLookupError, ValueError):
        return False
    except PermissionError:
        return True
    return True


def previous_run(out, comm):
    """The summary of a run already in ``out`` (with a 'description'), or None."""
    result = None
    if comm.rank == 0:
        try:
            result = json.loads((out / "summary.json").read_text())
        except FileNotFoundError:
            if any((out / name).exists() for name in checkpoint.GENERATIONS):
                result = {"status": "running", "steps_done": "?"}
        except (OSError, ValueError):
            result = {"status": "unreadable", "steps_done": "?"}
        if result is not None:
            status = result.get("status")
            kind = {"running": "an interrupted run", "interrupted": "an interrupted run",
                    "failed": "a failed run"}.get(status, f"a finished run ({status})")
            result["description"] = (f"{kind} of {result.get('example', '?')} "
                                     f"({result.get('steps_done')} steps done)")
    return comm.bcast(result, root=0)


def remove_run_files(out, comm):
    if comm.rank == 0:
        for path in [out / name for name in RUN_FILES] + list(out.glob("fields*.xdmf")) + \
                list(out.glob("fields*.h5")) + list(out.glob("fields*.xdmf.bak")):
            if path.exists():
                path.unlink()
