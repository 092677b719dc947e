"""A stop signal received by some ranks of a sweep, passed on to every rank, so that the whole
sweep stops as one: every point in progress at the end of its current step, with its
checkpoint and the status "interrupted", and every rank with the exit status 128 + signal,
ending normally (no rank is aborted, so mpirun prints nothing of its own).

The ranks of a sweep run their points independently (each alone, or in groups of ranks): a
rank that received SIGTERM while the others are busy with their own points cannot join them in
a collective call. Instead (``StopNotice``):

* a rank whose point or sweep stops on a signal sends the signal number to every other rank
  (``send``, non-blocking point-to-point messages on a private duplicate of the communicator);
* every rank looks for such a message between its points and after every step of its point
  (``check``, the run's ``on_step``) and, when one has come, stops as if the signal had arrived
  there (``signals.forward_stop``: at the end of the step, with a checkpoint);
* after their points, or their stop, all ranks meet (``settle``): every message sent is
  received, and a rank that finished its points before the message came stops with the same
  signal.
"""
from __future__ import annotations

import signal

from mpi4py import MPI


class StopNotice:
    """The stop notices of one sweep call on ``comm`` (see the module's docstring)."""

    TAG = 4243

    def __init__(self, comm):
        self.comm = comm.Dup() if comm.size > 1 else None
        self.sent, self.got, self.requests = 0, {}, []

    def check(self, step=None):
        """Between points, and after every step of a point (the run's ``on_step``; returns
        None: the run goes on): a notice that has come stops this rank as the signal itself
        would (only the first one acts)."""
        if self.comm is None:
            return None
        status = MPI.Status()
        first = not self.got
        while self.comm.iprobe(source=MPI.ANY_SOURCE, tag=self.TAG, status=status):
            source = status.Get_source()
            self.got[source] = self.comm.recv(source=source, tag=self.TAG)
        if first and self.got and not self.sent:
            from damage_dolfinx.runtime.signals import forward_stop
            forward_stop(min(self.got.values()))
        return None

    def send(self, exc):
        """This rank stopped on a signal (``exc``: its interruption): every other rank is told,
        unless the stop came from them."""
        if self.comm is None or self.sent or self.got:
            return
        from damage_dolfinx.runtime.signals import RECEIVED
        self.sent = int(getattr(exc, "signum", 0) or RECEIVED["signum"] or signal.SIGINT)
        self.requests = [self.comm.isend(self.sent, dest=rank, tag=self.TAG)
                         for rank in range(self.comm.size) if rank != self.comm.rank]

    def settle(self) -> int:
        """Collective, every rank after its points or its stop: every notice received; returns
        the signal the sweep stops on (0: none)."""
        if self.comm is None:
            return 0
        senders = self.comm.allgather(self.sent)
        for source, signum in enumerate(senders):
            if signum and source != self.comm.rank and source not in self.got:
                self.got[source] = self.comm.recv(source=source, tag=self.TAG)
        MPI.Request.Waitall(self.requests)
        self.comm.Free()
        self.comm = None
        return min((s for s in senders if s), default=0)
