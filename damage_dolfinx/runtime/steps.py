"""The run step by step in the caller's own loop (:func:`damage_dolfinx.steps`):
:class:`Steps` is both an iterator over the run's steps and a context manager.

Why the context manager. When a plain ``for step in dd.steps(...)`` loop ends, Python closes
the run's generator in the same way whether the loop body executed ``break`` or raised: the
generator receives ``GeneratorExit`` with the caller's exception out of its sight (CPython
stores the exception in flight while it finalises the generator). A raise is then taken for a
stop ("stopped", with the outputs of a stopping step). Under MPI a rank that raised alone
would write those outputs collectively while the others solve the next step, and wait for
ever: so, in dd.steps on several ranks, the ranks agree after every hand-over of a step
whether their callers left the loop (:func:`together`, one allgather of a flag); when only
some did, they end their run without any collective call, and the others raise
:class:`LoopLeft` with summary.json "failed". Inside ``with dd.steps(...) as run:`` the exit
sees the exception itself:

* the body raised (on any rank): the run is abandoned without any collective call
  (``Run.abandon``), then the call's outcome is decided on every rank
  (runtime/collective.py: one line, the status "failed" with the error in summary.json, one
  exception everywhere; a rank left alone aborts the job after ``FAIL_WAIT`` seconds rather
  than wait);
* the body left the loop early (``break``) or ended: the run stops at that step with its
  outputs and a checkpoint (status "stopped"), or has completed.
"""
from __future__ import annotations


class LoopLeft(RuntimeError):
    """dd.steps under MPI: the loop ended on some ranks (an exception of the loop body, or a
    break the others did not take) while this rank went on."""

    exit_status = 3


#: what a rank says after each hand-over: its caller goes on, left the loop (a stop), or
#: raised inside the loop (the script ended on an uncaught exception: the run is abandoned)
GOING_ON, LEAVING, ABANDONING = 0, 1, 2


def together(run, leaving: int) -> bool:
    """After each hand-over of a step (``run.handshake``: dd.steps on several ranks), every
    rank says whether its caller goes on, left the loop there or raised (one allgather of a
    small int; nothing on one rank or for dd.run, whose callback is decided by
    runtime/callbacks.decide). Returns True when the outputs of a stop may be written (every
    rank leaves, none raised, or no handshake). Otherwise the leaving ranks return False (they
    write nothing collective and end their run) and the ranks that went on mark summary.json
    "failed" and raise :class:`LoopLeft`, so that no rank waits for another that will never
    come."""
    comm = run.comm
    if not run.handshake or comm.size == 1:
        return True
    said = comm.allgather(int(leaving))
    left = [rank for rank, flag in enumerate(said) if flag]
    raised = [rank for rank, flag in enumerate(said) if flag == ABANDONING]
    if not left or (len(left) == comm.size and not raised):
        return True
    if leaving:
        return False
    n = run.stepper.n
    why = (f"the loop body raised on rank(s) {', '.join(map(str, raised))}" if raised else
           "an exception of its loop body, or a break the others did not take; 'with "
           "dd.steps(...) as run:' records the exception itself")
    error = LoopLeft(f"the loop over the steps ended on rank(s) {', '.join(map(str, left))} at "
                     f"step {n} while the others went on ({why}); the run is stopped without "
                     "the outputs of a stop")
    if comm.rank == min(set(range(comm.size)) - set(left)):
        from damage_dolfinx.runtime.collective import mark
        mark(run.out, error)
    raise error


class Steps:
    """The steps of one prepared run (``Run.prepare``): iterate over it, or use it as a
    context manager around the loop (see the module's docstring)."""

    def __init__(self, run, comm, within=None):
        self._run, self._comm = run, comm
        run.handshake = True
        self._steps = run.steps() if within is None else within(run.steps())
        self._outcome = None
        from damage_dolfinx.runtime.callbacks import opened
        opened(self)  # closed at the script's end if the caller left it open

    # -- the iterator
    def __iter__(self):
        return self

    def __next__(self):
        return next(self._steps)

    def close(self):
        """Stop the run at the current step (status "stopped", outputs and a checkpoint);
        collective: every rank stops at the same step."""
        self._steps.close()

    def _end_at_exit(self, uncaught):
        """The script ended with this iterator open (runtime/callbacks.close_at_exit): after an
        uncaught exception the run is abandoned ("failed" with that error), else it stops at
        its current step ("stopped", with its outputs and a checkpoint)."""
        if self._steps.gi_frame is None:  # finished or closed already
            return
        if uncaught is not None:
            try:
                self._run.abandon(self._steps, tell=True)
            finally:
                from damage_dolfinx.runtime.collective import mark
                if self._comm.rank == 0:
                    mark(self._run.out, uncaught)
            return
        self._steps.close()

    @property
    def summary(self):
        """The run's summary so far (None before its set-up)."""
        return self._run.summary

    # -- the context manager
    def __enter__(self):
        from damage_dolfinx.runtime.collective import outcome
        self._outcome = outcome(self._comm)
        self._outcome.__enter__()
        return self

    def __exit__(self, exc_type, exc, tb):
        decide, self._outcome = self._outcome, None
        if exc is not None:  # the body raised: no stopping outputs, no collective call
            try:
                self._run.abandon(self._steps)
            except Exception:  # noqa: BLE001 - the body's exception is the outcome
                pass
            return decide.__exit__(exc_type, exc, tb)
        try:
            self._steps.close()  # a break: stopped here (a finished run: nothing to do)
        except BaseException as error:  # noqa: BLE001 - decided on every rank
            if not decide.__exit__(type(error), error, error.__traceback__):
                raise
            return False
        return decide.__exit__(None, None, None)
