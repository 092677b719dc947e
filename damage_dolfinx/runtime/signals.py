"""Signals: SIGTERM, SIGINT and SIGUSR1 stop a run at the end of the current step,
with a checkpoint, status "interrupted" and exit status 128 + signal (RunInterrupted)."""
from __future__ import annotations

import os
import signal
import threading
import time

#: signals that stop a run at the end of the current step, with a checkpoint; mpirun (Open MPI)
#: forwards SIGUSR1 to every rank, while it answers SIGTERM/SIGINT by killing the ranks
STOP_SIGNALS = (signal.SIGTERM, signal.SIGINT, signal.SIGUSR1)


class RunInterrupted(Exception):
    """The run stopped on a signal after writing a checkpoint; exit status 128 + signal."""

    def __init__(self, signum: int, message: str):
        super().__init__(message)
        self.signum, self.exit_status = signum, 128 + signum


class StopSignals:
    """While active, STOP_SIGNALS only set ``signum`` (the runner stops collectively at the end
    of the step); a signal repeated ``FORCE_AFTER`` seconds later ends the process at once (the
    signal's default action). Earlier repeats are the same request arriving twice (a scheduler
    signals every process and mpirun forwards it too) and are ignored."""

    FORCE_AFTER = 5.0

    def __enter__(self):
        self.signum, self._previous, self._first = 0, {}, None
        if threading.current_thread() is threading.main_thread():
            self._previous = {s: signal.signal(s, self._handle) for s in STOP_SIGNALS}
        return self

    def _handle(self, signum, frame):
        now = time.monotonic()
        if self.signum and now - self._first >= self.FORCE_AFTER:
            signal.signal(signum, signal.SIG_DFL)
            os.kill(os.getpid(), signum)
        if not self.signum:
            self.signum, self._first = signum, now

    def __exit__(self, *exc):
        for s, handler in self._previous.items():
            signal.signal(s, handler if not self.signum else self._late)

    def _late(self, signum, frame):
        """After a stop: a duplicate of the request is still ignored; a later signal gets the
        handler that was there before the run."""
        if time.monotonic() - self._first < self.FORCE_AFTER:
            return
        for s, handler in self._previous.items():
            signal.signal(s, handler)
        os.kill(os.getpid(), signum)
