"""Signals: SIGTERM, SIGINT and SIGUSR1 stop a run at the end of the current step,
with a checkpoint, status "interrupted" and exit status 128 + signal (RunInterrupted)."""
from __future__ import annotations

import contextlib
import os
import signal
import threading
import time

#: signals that stop a run at the end of the current step, with a checkpoint; mpirun (Open MPI)
#: forwards SIGUSR1 to every rank, while it answers SIGTERM/SIGINT by killing the ranks
STOP_SIGNALS = (signal.SIGTERM, signal.SIGINT, signal.SIGUSR1)


from damage_dolfinx.core.errors import RunInterrupted  # noqa: F401


#: the first stop signal this process received (0: none); a failure while one is pending is an
#: interruption (a compiler killed by the terminal's SIGINT fails the JIT compile)
RECEIVED = {"signum": 0}


class SignalStop(KeyboardInterrupt):
    """A stop signal outside a run's time loop (the command line's handler): the command
    stops where it is, exit status 128 + signal."""

    def __init__(self, signum: int):
        super().__init__(f"stopped by {signal.Signals(signum).name}")
        self.signum, self.exit_status = signum, 128 + signum


def stop_outside_runs(signum, frame):
    """Handler of the command line for SIGTERM, SIGINT and SIGUSR1 outside a run's loop
    (set-up, a convergence study, a sweep between points): raise SignalStop.

    Not inside an import (a module half imported would break the command's way out with a
    traceback): there the stop is delivered again shortly after (:func:`_again`), as it is
    until the command has taken it (:func:`taken`), since Python drops an exception raised in
    a finaliser or a weakref callback ("Exception ignored in ...")."""
    RECEIVED["signum"] = RECEIVED["signum"] or signum
    _PENDING["taken"] = False
    _again(signum)
    if _in_import(frame):
        return
    raise SignalStop(signum)


#: a stop of the command line's handler not yet taken by the command (see stop_outside_runs)
_PENDING = {"taken": True}
#: seconds between two deliveries of a stop not yet taken
AGAIN_AFTER = 0.1


def taken():
    """The command has taken its stop (it prints the line and ends): no delivery again."""
    _PENDING["taken"] = True


def _in_import(frame) -> bool:
    while frame is not None:
        if frame.f_code.co_filename.startswith("<frozen importlib"):
            return True
        frame = frame.f_back
    return False


def _again(signum):
    def deliver():
        import _thread
        if not _PENDING["taken"] and signal.getsignal(signum) is stop_outside_runs:
            _thread.interrupt_main(signum)
    timer = threading.Timer(AGAIN_AFTER, deliver)
    timer.daemon = True
    timer.start()


@contextlib.contextmanager
def keeping_sigint():
    """Within it, an import that resets SIGINT (gmsh's module does; DOLFINx's io imports gmsh
    where it is installed, in some versions) leaves the handler as it was (main thread)."""
    main = threading.current_thread() is threading.main_thread()
    handler = signal.getsignal(signal.SIGINT) if main else None
    try:
        yield
    finally:
        if handler is not None:
            signal.signal(signal.SIGINT, handler)


from damage_dolfinx.compat.gmsh import import_gmsh_keeping_sigint  # noqa: E402,F401


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
        _ACTIVE.append(self)
        if not _PENDING["taken"] and RECEIVED["signum"]:  # a stop not yet taken (it came
            _PENDING["taken"] = True                        # inside an import): now
            self.request(RECEIVED["signum"])
        return self

    def request(self, signum):
        """The stop ``signum`` asked for from elsewhere (another rank received it): the run
        stops at the end of its step as if the signal had arrived here."""
        if not self.signum:
            self.signum, self._first = signum, time.monotonic()
            RECEIVED["signum"] = RECEIVED["signum"] or signum

    def _handle(self, signum, frame):
        now = time.monotonic()
        if self.signum and now - self._first >= self.FORCE_AFTER:
            signal.signal(signum, signal.SIG_DFL)
            os.kill(os.getpid(), signum)
        if not self.signum:
            self.signum, self._first = signum, now
            RECEIVED["signum"] = RECEIVED["signum"] or signum

    def __exit__(self, *exc):
        if self in _ACTIVE:
            _ACTIVE.remove(self)
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


#: the StopSignals of the run in progress in this process (innermost last)
_ACTIVE: list = []


def forward_stop(signum):
    """A stop signal another rank received, acted on here as if it had arrived here: the run in
    progress stops at the end of its step (``StopSignals.request``); outside a run the
    command stops where it is (SignalStop)."""
    if _ACTIVE:
        _ACTIVE[-1].request(signum)
        return
    RECEIVED["signum"] = RECEIVED["signum"] or signum
    raise SignalStop(signum)
