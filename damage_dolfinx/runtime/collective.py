"""One decided outcome on every rank: an exception raised on any rank (ours or the user's code,
a load function or a damage law raising on one rank only) ends every rank within seconds, with
one line, the status in the folder's summary.json and one exit status.

Mechanism (``outcome``): the command or API call runs inside ``with outcome(comm):``. When it
ends, every rank joins an agreement on a private duplicate of the communicator (its own
collectives never mix with those of the run):

* a rank that succeeded waits there for the others (a rank that failed either joins or aborts
  the job, so this wait ends);
* a rank that raised joins with its exception; if every rank arrives within ``FAIL_WAIT``
  seconds (the error was collective, or the others finished), the ranks exchange their
  outcomes and every rank raises the same decided exception (the lowest failing rank's), so the
  caller, or the command line, sees one outcome everywhere;
* if some rank does not arrive (it is blocked in a collective call the failing rank left: a
  barrier, an allreduce, a PETSc solve), the failing rank records the status in the summary of
  the folder it was writing, prints the one line itself and aborts the job with the exit status
  of its error (``MPI_Abort``): nobody waits for ever.

Exit statuses (the command line's): 2 refused input, 3 failed (a solver, a state that cannot be
right, an exception of user code), 4 output error, 128 + signal for a signal.
"""
from __future__ import annotations

import contextlib
import json
import os
import sys
import time
from pathlib import Path

from mpi4py import MPI

#: a rank that raised waits this long for the others to join the agreement, then aborts
FAIL_WAIT = 5.0
#: run folders claimed during the current call (the status of a failure goes there)
_FOLDERS: list = []


class RankFailure(Exception):
    """Raised on the ranks that did not fail, with the failing rank's category and line."""

    def __init__(self, message, code, kind):
        super().__init__(message)
        self.exit_status, self.kind = code, kind


def classify(exc) -> tuple:
    """(exit status, prefix, status word) of an exception, the command line's convention."""
    from damage_dolfinx.core.parameters import InputError
    from damage_dolfinx.runtime.atomic import OutputError
    from damage_dolfinx.runtime.signals import RunInterrupted
    if isinstance(exc, RankFailure):
        return exc.exit_status, exc.kind, _STATUS[exc.kind]
    if isinstance(exc, InputError):
        return 2, "error", "refused"
    if isinstance(exc, OutputError):
        return 4, "output error", "failed"
    if isinstance(exc, RunInterrupted):
        return exc.exit_status, "", "interrupted"
    if isinstance(exc, KeyboardInterrupt):
        return getattr(exc, "exit_status", 130), "", "interrupted"
    if isinstance(exc, SystemExit):
        code = exc.code if isinstance(exc.code, int) else 1
        return code, "", "failed"
    from damage_dolfinx.runtime.signals import RECEIVED
    if RECEIVED["signum"]:  # whatever broke after a stop signal broke because of it
        return 128 + RECEIVED["signum"], "", "interrupted"
    from damage_dolfinx.numerics.solvers import ConvergenceError
    if isinstance(exc, ConvergenceError):
        return 3, "solver failure", "failed"
    return 3, "failed", "failed"


_STATUS = {"error": "refused", "output error": "failed", "": "interrupted",
           "solver failure": "failed", "failed": "failed"}


def describe(exc) -> str:
    """The exception as one line (user code: its type and message)."""
    from damage_dolfinx.core.parameters import InputError
    from damage_dolfinx.runtime.atomic import OutputError
    from damage_dolfinx.runtime.signals import RunInterrupted
    from damage_dolfinx.numerics.solvers import ConvergenceError
    from damage_dolfinx.runtime.signals import RECEIVED
    if isinstance(exc, KeyboardInterrupt) or (RECEIVED["signum"] and not isinstance(
            exc, RunInterrupted)):
        import signal
        name = signal.Signals(RECEIVED["signum"] or signal.SIGINT).name
        return f"stopped by {name} before the end (no checkpoint of this stage: a rerun " \
               "starts it again)"
    text = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
    if isinstance(exc, (InputError, OutputError, RunInterrupted, ConvergenceError, RankFailure)):
        return text or type(exc).__name__
    where = _user_frame(exc)
    return f"{type(exc).__name__}: {text}" + (f" (in {where})" if where else "")


def _user_frame(exc) -> str:
    """'file:line' of the innermost frame outside this package and the libraries (the user's
    code), or ''."""
    import traceback
    package = str(Path(__file__).resolve().parents[1])
    found = ""
    for frame in traceback.extract_tb(exc.__traceback__):
        name = frame.filename
        if name.startswith(package) or "site-packages" in name or "dist-packages" in name \
                or name.startswith("<") or "/lib/python" in name:
            continue
        found = f"{Path(name).name}:{frame.lineno}"
    return found


def line(exc, rank=None) -> str:
    """The one line printed for ``exc`` (``rank``: named when it failed alone)."""
    code, kind, _ = classify(exc)
    text = describe(exc)
    where = f" (rank {rank})" if rank is not None else ""
    return f"damage-dolfinx: {kind + ': ' if kind else ''}{text}{where}"


#: folders this process created (removed again, if still empty, when the call is refused)
_CREATED: list = []


def created(folder):
    _CREATED.append(Path(folder))


def _tidy(exc, rank):
    """A refused call leaves no empty folder it created."""
    from damage_dolfinx.core.parameters import InputError
    folders, _CREATED[:] = list(_CREATED), []
    if rank != 0 or not isinstance(exc, InputError):
        return
    for folder in reversed(folders):
        try:
            folder.rmdir()  # only if empty
        except OSError:
            pass


def track(folder, kind="run"):
    """Note a folder this process writes into (its summary.json receives a failure's status)."""
    _FOLDERS.append((Path(folder), kind))


def mark(folder, exc, rank=None, kind=None):
    """Record a failure in ``folder``/summary.json if the run there has not recorded an outcome
    itself (status 'running' or no summary); only a folder the package claimed (listed in a
    manifest) is written into."""
    folder = Path(folder)
    if not (folder / "manifest.json").is_file():
        return
    path = folder / "summary.json"
    try:
        summary = json.loads(path.read_text())
        if not isinstance(summary, dict):
            summary = {}
    except (OSError, ValueError):
        summary = {}
    unfinished = (None, "running") + (("incomplete", "completed") if kind == "sweep" else ())
    if summary.get("status") not in unfinished:  # the run recorded its own outcome
        return
    _, _, status = classify(exc)
    schema = {"run": "damage-dolfinx/summary/v1", "study": "damage-dolfinx/convergence/v1",
              "sweep": "damage-dolfinx/sweep/v1"}.get(kind)
    if schema and "schema" not in summary:
        summary["schema"] = schema
    summary.update(status="failed" if status == "refused" else status, error=describe(exc))
    if rank is not None:
        summary["failed_rank"] = rank
    from damage_dolfinx.runtime.atomic import write_json
    try:
        write_json(path, summary, MPI.COMM_SELF)
        return
    except Exception:  # noqa: BLE001 - a full disk: the reserve, else in place
        pass
    try:
        if _free_reserve(folder):
            write_json(path, summary, MPI.COMM_SELF)
            return
    except Exception:  # noqa: BLE001
        pass
    _in_place(path, summary)  # the line and the exit status tell in any case


def _free_reserve(folder) -> bool:
    """Give back the disk space the folder's lock reserves (runfolder.RunLock), when this
    process holds it. True if space was freed."""
    lock = Path(folder) / ".lock"
    try:
        with open(lock, "r+b") as f:
            header = f.readline()
            if not header.startswith(f"pid {os.getpid()} ".encode()) or \
                    os.fstat(f.fileno()).st_size <= len(header):
                return False
            f.truncate(len(header))
        return True
    except OSError:
        return False


def _in_place(path, summary):
    """The last resort on a full disk without a reserve: the status written over the existing
    summary.json, within the blocks it already has (no new space needed). A kill during this
    write leaves a summary that the next restart rebuilds from what is on disk."""
    try:
        text = (json.dumps(summary, indent=1, default=str) + "\n").encode()
        with open(path, "r+b") as f:
            if len(text) > os.fstat(f.fileno()).st_blocks * 512:
                return
            f.write(text)
            f.truncate(len(text))
            f.flush()
            os.fsync(f.fileno())
    except (OSError, ValueError):
        pass


@contextlib.contextmanager
def outcome(comm=MPI.COMM_WORLD):
    """Run the body; on every rank the same outcome (see the module's docstring)."""
    if not _LOCAL.depth:  # a new call: no signal yet
        from damage_dolfinx.runtime.signals import RECEIVED
        RECEIVED["signum"] = 0
    if comm.size == 1 or _LOCAL.depth:
        _LOCAL.depth = getattr(_LOCAL, "depth", 0) + 1
        start = len(_FOLDERS)
        try:
            yield
        except BaseException as exc:
            _taken(exc)
            if comm.size == 1 and _LOCAL.depth == 1:
                for folder, kind in _FOLDERS[start:]:
                    mark(folder, exc, kind=kind)
                _tidy(exc, 0)
            raise
        finally:
            _LOCAL.depth -= 1
            if _LOCAL.depth == 0:
                del _FOLDERS[start:]
                _CREATED.clear()
        return
    agree = comm.Dup()
    _LOCAL.depth = 1
    start = len(_FOLDERS)
    failure = None
    try:
        yield
    except BaseException as exc:  # noqa: BLE001 - every exception is decided collectively
        _taken(exc)
        failure = exc
    finally:
        _LOCAL.depth = 0
    folders = list(_FOLDERS[start:])
    del _FOLDERS[start:]
    mine = None if failure is None else (comm.rank, *classify(failure)[:2], describe(failure))
    request = agree.Ibarrier()
    deadline = time.monotonic() + FAIL_WAIT
    while not request.Test():
        if failure is not None and time.monotonic() > deadline:
            _abort(comm, failure, folders)
        time.sleep(0.002)
    outcomes = agree.allgather(mine)
    failed = [o for o in outcomes if o is not None]
    if not failed:
        agree.Free()
        _CREATED.clear()
        return
    rank, code, kind, text = failed[0]
    _tidy(failure if failure is not None and rank == comm.rank else
          (InputError_() if code == 2 else None), comm.rank)
    alone = rank if len(failed) < comm.size else None
    if comm.rank == 0:
        exc = failure if failure is not None else RankFailure(text, code, kind)
        for folder, where in folders:
            mark(folder, exc, alone, where)
    agree.Barrier()  # the status is on disk before any rank's caller sees the exception
    agree.Free()
    if failure is not None and (rank == comm.rank or classify(failure)[:2] == (code, kind)):
        raise failure  # this rank's own exception is of the decided kind: the caller's catch
    raise decided(text + (f" (rank {rank})" if len(failed) < comm.size else ""), code,
                  kind) from failure


def _taken(exc):
    """A stop signal's exception reached the call: it is not delivered again
    (signals.stop_outside_runs)."""
    if isinstance(exc, KeyboardInterrupt):
        from damage_dolfinx.runtime.signals import taken
        taken()


def decided(text, code, kind) -> RankFailure:
    """The decided failure on a rank that did not raise it: a RankFailure that is also of the
    package's exception of its kind (``except dd.InputError`` catches it on every rank)."""
    from damage_dolfinx.core.parameters import InputError
    from damage_dolfinx.runtime.atomic import OutputError
    from damage_dolfinx.numerics.solvers import ConvergenceError
    base = {"error": InputError, "output error": OutputError,
            "solver failure": ConvergenceError}.get(kind)
    if base is None:
        return RankFailure(text, code, kind)
    cls = _DECIDED.get(base)
    if cls is None:
        cls = _DECIDED[base] = type(base.__name__, (RankFailure, base), {})
    return cls(text, code, kind)


_DECIDED: dict = {}


def InputError_():
    from damage_dolfinx.core.parameters import InputError
    return InputError("")


class _Local:
    depth = 0


_LOCAL = _Local()


def _abort(comm, exc, folders):
    """The others are blocked: status, the one line, and the job ended with the exit status."""
    for folder, where in folders:
        mark(folder, exc, comm.rank, where)
    code = classify(exc)[0]
    try:
        print(line(exc, comm.rank) + "; the other ranks were waiting: job aborted",
              file=sys.stderr, flush=True)
    finally:
        sys.stdout.flush()
        comm.Abort(code)
        os._exit(code)
