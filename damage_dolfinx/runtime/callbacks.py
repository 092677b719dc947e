"""A user's callback is a collective decision: whatever ``on_step`` returns or raises on one
rank, every rank learns it at the same step and acts alike (no rank waits for another that
took another road).

Mechanism (:func:`decide`): the callback runs on every rank; its outcome (stop or go on, or
the exception it raised) is exchanged in one allgather of a small tuple on the run's
communicator, which every rank reaches after the same step. Then

* an exception on some ranks only ends the call on every rank with the same exception,
  :class:`CallbackFailed` naming the first raising rank and its error (the user's exception
  is its ``__cause__`` where it was raised; the status "failed" goes into summary.json,
  runtime/collective.py); an exception on every rank is re-raised as it is, as on one rank;
* a stop (a true return value) asked on any rank stops every rank at that step (status
  "stopped", with its outputs and a checkpoint); when only some ranks asked, one warning line
  names them.

A return value whose truth is not a plain yes or no (a NumPy array of several values, an
object whose ``__bool__`` raises) is the callback's error, and so is a ``sys.exit`` inside it
(a script ending in a callback would leave the run "running" behind exit status 0).

An iterator of :func:`damage_dolfinx.steps` left open when the script ends is closed before
MPI is finalised (:func:`close_at_exit`): the run stops at its current step with its outputs
and a checkpoint ("stopped"), or, when the script ended on an uncaught exception, is abandoned
with the status "failed" and that error.
"""
from __future__ import annotations

import atexit
import sys
import weakref


class CallbackFailed(RuntimeError):
    """A user's callback raised on another rank (this rank's callback did not)."""

    exit_status = 3


def _truth(value) -> bool:
    try:
        return bool(value)
    except Exception as exc:  # noqa: BLE001 - the callback's own error
        raise TypeError(f"on_step returned {type(value).__name__} whose truth is not a plain "
                        f"yes or no ({exc}); return True to stop, False or None to go on") \
            from None


def decide(comm, callback, *args, name="on_step", step=None) -> bool:
    """Call ``callback(*args)`` and agree on its outcome with every rank of ``comm``; True:
    every rank stops here. Raises on every rank when the callback raised on any."""
    error = None
    try:
        stop = _truth(callback(*args))
    except SystemExit as exc:
        error = RuntimeError(f"{name} called sys.exit({exc.code!r}) (a callback cannot end "
                             "the script; return True to stop the run)")
        error.__cause__ = None
        stop = False
    except BaseException as exc:  # noqa: BLE001 - decided on every rank
        error, stop = exc, False
    if comm.size == 1:
        if error is not None:
            raise error
        return stop
    from damage_dolfinx.runtime.collective import describe
    mine = (stop, None if error is None else describe(error))
    everyone = comm.allgather(mine)
    failed = [(rank, text) for rank, (_, text) in enumerate(everyone) if text is not None]
    if failed:
        if error is not None and len(failed) == comm.size:  # alike everywhere: as on one rank
            raise error
        rank, text = failed[0]
        raise CallbackFailed(f"{name} raised on rank {rank}" +
                             (f" at step {step}" if step is not None else "") + f": {text}") \
            from error
    asked = [rank for rank, (flag, _) in enumerate(everyone) if flag]
    if asked and len(asked) < comm.size and comm.rank == 0:
        print(f"WARNING: {name} asked to stop on rank(s) {', '.join(map(str, asked))} only"
              + (f" at step {step}" if step is not None else "") + "; every rank stops there "
              "(decide from collective values to stop alike)", file=sys.stderr, flush=True)
    return bool(asked)


#: the dd.steps iterators not yet closed (closed at the script's end, before MPI finalises)
_OPEN: "weakref.WeakSet" = weakref.WeakSet()


def opened(steps):
    _OPEN.add(steps)


def close_at_exit():
    """The script ended with a dd.steps iterator open: stop its run (or abandon it after an
    uncaught exception), so that no "running" summary stays behind the script's end."""
    uncaught = getattr(sys, "last_value", None)
    for steps in list(_OPEN):
        try:
            steps._end_at_exit(uncaught)
        except BaseException as exc:  # noqa: BLE001 - the script has ended: one line
            from damage_dolfinx.runtime.collective import line
            try:
                print(line(exc), file=sys.stderr, flush=True)
            except Exception:  # noqa: BLE001
                pass


atexit.register(close_at_exit)
