"""The output folder: its lock (a second run into a folder where one is live is refused; a dead
run's lock, even after SIGKILL, never blocks), the run it already holds, its manifest (what the
package wrote in it: --overwrite removes exactly that, and a file the package did not write is
never touched), the rank-0 decision every rank receives (``decided``) and the lock of a
folder shared by separate processes (``shared_folder_lock``); mesh files: meshfile.py."""
from __future__ import annotations

import contextlib
import fcntl
import json
import math
import os
import re
import socket
import time
from pathlib import Path

from mpi4py import MPI

from damage_dolfinx.runtime import checkpoint
from damage_dolfinx.core.parameters import InputError

#: files of a run written before manifests existed (what --overwrite removes there, with the
#: outputs its summary.json names)
RUN_FILES = ("summary.json", "history.csv", "fields_final.npz", "checkpoint.json",
             *checkpoint.GENERATIONS)


class RunLive(InputError):
    """A run is live in the folder (its lock is held): refused, and nothing there touched."""


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
            raise (RunLive if error.startswith("a run is live") else InputError)(error)

    def _acquire(self):
        for _ in range(10):  # the file may be replaced between open and flock (see release)
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                holder = os.read(fd, 1000).decode(errors="replace").split("\n")[0]
                os.close(fd)
                if holder.split()[:2] == ["pid", str(os.getpid())]:  # e.g. a notebook's cell
                    return (f"a run is live in {str(self.path.parent)!r} in this same process "
                            f"(a dd.steps not yet closed); close it first (run.close(), or "
                            f"leave its with block)")
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


@contextlib.contextmanager
def shared_folder_lock(out, comm):
    """Hold ``out/.sweep.lock`` (SWEEP_LOCK) locked (rank 0, flock; lockf where the file
    system has no flock) for the body: separate processes writing the same folder (the jobs
    of a job array, each running points of one sweep) take turns there. Waits for the holder;
    the kernel drops a dead holder's lock. The file stays (never unlinked, so no two holders
    can ever hold two different files)."""
    fd, error, name = None, None, SWEEP_LOCK
    if comm.rank == 0:
        try:
            fd = os.open(Path(out) / name, os.O_RDWR | os.O_CREAT, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX)
            except OSError:  # no flock here (some network file systems): POSIX record locks
                fcntl.lockf(fd, fcntl.LOCK_EX)
        except OSError as exc:
            if fd is not None:
                os.close(fd)
                fd = None
            error = f"cannot lock {str(Path(out) / name)!r}: {exc.strerror or exc}"
    error = comm.bcast(error, root=0)
    if error:
        raise InputError(error)
    try:
        yield
    finally:
        if fd is not None:
            os.close(fd)  # releases the lock


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


def _summary_problem(data, kind="run"):
    """What is wrong with a summary read from disk (None: usable)."""
    schema = {"run": "damage-dolfinx/summary/v1", "study": "damage-dolfinx/convergence/v1"}[kind]
    if not isinstance(data, dict):
        return "not a JSON object"
    if data.get("schema") != schema:
        return f"schema {data.get('schema')!r}, expected {schema!r}"
    if kind == "run":
        steps, t = data.get("steps_done"), data.get("t_final")
        if not isinstance(data.get("status"), str):
            return "no status"
        if isinstance(steps, bool) or not isinstance(steps, int) or steps < 0:
            return f"steps_done = {steps!r} is not a whole number >= 0"
        if isinstance(t, bool) or not isinstance(t, (int, float)) or not math.isfinite(t):
            return f"t_final = {t!r} is not a finite number"
    return None


def previous_run(out, comm):
    """The summary of a run already in ``out`` (with a 'description'), or None. A summary that
    cannot be read or is not a run's summary counts as an unreadable run (a restart then
    relies on the checkpoint alone; see checkpoint.resume_point)."""
    result = None
    if comm.rank == 0:
        try:
            result = json.loads((out / "summary.json").read_text())
            problem = _summary_problem(result)
            if problem:
                result = {"status": "unreadable", "steps_done": "?",
                          "problem": f"summary.json: {problem}"}
        except FileNotFoundError:
            if any((out / name).exists() for name in checkpoint.GENERATIONS):
                result = {"status": "running", "steps_done": "?"}
        except (OSError, ValueError) as exc:
            result = {"status": "unreadable", "steps_done": "?",
                      "problem": f"summary.json: {type(exc).__name__}"}
        if result is not None:
            status = result.get("status")
            kind = {"running": "an interrupted run", "interrupted": "an interrupted run",
                    "failed": "a failed run", "unreadable": "a run with an unreadable summary"
                    }.get(status, f"a finished run ({status})")
            result["description"] = (f"{kind} of {result.get('example', '?')} "
                                     f"({result.get('steps_done')} steps done)")
    return comm.bcast(result, root=0)


# ---------------------------------------------------------------------------- the manifest
#: what the package wrote in a folder: {"schema", "kind": "run" | "study", "files": [names]}
MANIFEST = "manifest.json"
MANIFEST_SCHEMA = "damage-dolfinx/manifest/v1"
#: names the package uses for its own bookkeeping (a run's lock, a sweep folder's lock)
HIDDEN = (".lock", ".sweep.lock")
#: the lock file of a folder shared by separate processes (a sweep's jobs): shared_folder_lock
SWEEP_LOCK = HIDDEN[1]
#: the writability probe of io.prepare_output_dir (PROBE + pid, there for an instant)
PROBE = ".damage-dolfinx-write-test-"
#: files of a convergence study
STUDY_FILES = ("summary.json", "errors.csv", "errors.md", "convergence.png")
_LEGACY_FIELDS = re.compile(r"fields(_from_step\d+)?\.(xdmf|h5|xdmf\.bak)$")


def _ours(name, files) -> bool:
    """``name`` is a listed file or the temporary file of one (atomic.py: NAME.tmp)."""
    return name in files or (name.endswith(".tmp") and name[:-4] in files) or name in HIDDEN \
        or name.startswith(PROBE)


def read_manifest(out):
    """(kind, set of names) of ``out``'s manifest, or None without one; raises InputError
    for a manifest that cannot be used (rank 0)."""
    path = Path(out) / MANIFEST
    if not path.exists():
        return None
    try:
        data = json.loads(path.read_text())
        files = data["files"]
        if data.get("schema") != MANIFEST_SCHEMA or data.get("kind") not in ("run", "study", "sweep") \
                or not isinstance(files, list) or not all(
                    isinstance(f, str) and f and "/" not in f and f not in (".", "..")
                    for f in files):
            raise ValueError("not a damage-dolfinx manifest")
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise InputError(f"{str(path)!r} is unreadable ({exc}); nothing in {str(out)!r} was "
                         "touched: move the folder aside or choose another out folder") from None
    return data["kind"], set(files) | {MANIFEST}


def _legacy(out):
    """(kind, names) of a folder written before manifests existed, from its summary (exact
    names, never a pattern that could match a user's file), or None."""
    try:
        summary = json.loads((out / "summary.json").read_text())
    except (OSError, ValueError):
        summary = None
    if isinstance(summary, dict) and summary.get("schema") == "damage-dolfinx/convergence/v1":
        return "study", set(STUDY_FILES)
    run = isinstance(summary, dict) and summary.get("schema") == "damage-dolfinx/summary/v1"
    if not run and not any((out / name).exists() for name in checkpoint.GENERATIONS):
        return None
    names = set(RUN_FILES) | {n.name for n in out.iterdir() if _LEGACY_FIELDS.match(n.name)}
    if run:
        outputs = summary.get("outputs") if isinstance(summary.get("outputs"), dict) else {}
        for key in ("xdmf", "history", "final_fields"):
            if isinstance(outputs.get(key), str):
                names.add(outputs[key])
        for fig in outputs.get("figures") or []:
            if isinstance(fig, dict) and isinstance(fig.get("file"), str):
                names.add(fig["file"])
    return "run", {n for n in names if "/" not in n}


def folder_contents(out):
    """(kind or None, the package's files present, the other files present) of ``out``
    (rank 0); InputError for an unusable manifest."""
    out = Path(out)
    present = {p.name for p in out.iterdir()} if out.is_dir() else set()
    known = read_manifest(out) or _legacy(out)
    kind, files = known if known else (None, set())
    ours = {n for n in present if _ours(n, files)}
    return (kind if ours - {MANIFEST, *HIDDEN} or known and MANIFEST in present else None,
            ours, present - ours)


def _listing(names, limit=4) -> str:
    names = sorted(names)
    return ", ".join(names[:limit]) + (f" and {len(names) - limit} more" if len(names) > limit
                                       else "")


def claim_folder(out, kind, planned, restart, overwrite, comm, description=None, apply=True):
    """The folder rules of ``run`` and ``converge``, before any work (rank 0 decides, every
    rank gets the answer): a folder holding the other kind is refused; one holding the same
    kind is refused unless ``restart`` (kept) or ``overwrite`` (exactly the files its
    manifest lists are removed); files the package did not write are never touched: a folder
    holding such files and no manifest is refused, and so is one where a file the package is
    about to write (``planned``, names) exists without being the package's. Then the manifest
    lists ``planned`` (and what a restart keeps). Returns True when an earlier run/study of
    this kind is there (before any overwrite). Raises InputError. ``apply`` False: the checks
    alone (nothing removed, no manifest written)."""
    result = decided(comm, out, _claim, Path(out), kind, set(planned), restart, overwrite,
                     description, apply)
    if apply:
        from damage_dolfinx.runtime.collective import track
        track(out, kind)
    return result


def decided(comm, out, decide, *args):
    """``decide(*args)`` run on rank 0 alone (it reads and writes the folder ``out``), its
    result on every rank. An InputError it raises is raised on every rank, and so is an
    OSError, as an InputError naming ``out`` (one line: nothing was done)."""
    result = None
    if comm.rank == 0:
        try:
            result = decide(*args)
        except InputError as exc:
            result = exc
        except OSError as exc:
            result = InputError(f"cannot use {str(out)!r}: {exc.strerror or exc}")
    result = comm.bcast(result, root=0)
    if isinstance(result, InputError):
        raise result
    return result


def _claim(out, kind, planned, restart, overwrite, description, apply=True):
    found, ours, others = folder_contents(out)
    other_kind = {"run": "study", "study": "run"}[kind]
    what = {"run": "a run", "study": "a convergence study", "sweep": "a parameter sweep"}
    if found == "sweep" or (found is None and (out / "points.json").is_file()):
        found = "sweep"
        raise InputError(f"{str(out)!r} holds {what[found]}; {what[kind]} needs a folder of "
                         "its own: choose another --out (nothing was touched)")
    if found == other_kind:
        raise InputError(f"{str(out)!r} holds {what[other_kind]}; {what[kind]} needs a folder "
                         "of its own: choose another out folder (nothing was touched)")
    earlier = found == kind and bool(ours - {MANIFEST, *HIDDEN})
    if others and found is None:
        raise InputError(f"{str(out)!r} holds files damage-dolfinx did not write "
                         f"({_listing(others)}) and no {MANIFEST}: choose another out folder or an "
                         "empty folder (nothing was touched)")
    clash = others & {n for p in planned for n in (p, p + ".tmp")}
    if clash:
        raise InputError(f"{str(out)!r} holds {_listing(clash)}, not written by damage-dolfinx "
                         f"(not in its {MANIFEST}), where this {kind} would write: move "
                         "them or choose another out folder (nothing was touched)")
    if earlier and not restart and not overwrite:
        raise InputError(f"{str(out)!r} holds {description or what[kind]}; restart=True "
                         "continues it, overwrite=True replaces it, or choose another out folder")
    if not apply:
        return earlier
    keep = set()
    if earlier and overwrite and not restart:
        for name in sorted(ours - {MANIFEST, *HIDDEN}):
            path = out / name
            if path.is_file() or path.is_symlink():
                path.unlink()
    elif earlier:
        keep = ours - set(HIDDEN)
    write_manifest(out, kind, keep | planned)
    return earlier


def write_manifest(out, kind, files):
    from damage_dolfinx.runtime.atomic import write_json
    write_json(Path(out) / MANIFEST, {"schema": MANIFEST_SCHEMA, "kind": kind,
                                      "files": sorted(set(files) - {MANIFEST, *HIDDEN})},
               MPI.COMM_SELF)


def add_to_manifest(out, names, comm):
    """List ``names`` in ``out``'s manifest before they are written (rank 0)."""
    if comm.rank != 0:
        return
    known = read_manifest(out)
    if known is None:
        return
    kind, files = known
    if not set(names) <= files:
        write_manifest(out, kind, files | set(names))


# ---------------------------------------------------------------------------- mesh files
from damage_dolfinx.runtime.meshfile import check_mesh_file  # noqa: E402,F401 (re-exported)
