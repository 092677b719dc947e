"""How the ranks of a sweep agree while they run their points apart: one outcome for the ranks
of one point (``point_outcome``), the progress lines relayed to rank 0 (``Relay``), and a
stop signal received by some ranks passed on to every rank (``StopNotice``), so that the whole
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
import time

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
        would."""
        if self.comm is None:
            return None
        status = MPI.Status()
        while self.comm.iprobe(source=MPI.ANY_SOURCE, tag=self.TAG, status=status):
            source = status.Get_source()
            self.got[source] = self.comm.recv(source=source, tag=self.TAG)
        if self.got and not self.sent:  # (again at every call: no next point either)
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


def point_outcome(group, comm, folders, body):
    """``body()`` on every rank of ``group`` (the ranks running one point), with one outcome on
    all of them: its value, or the same exception everywhere (a failing rank's own, the others
    a collective.RankFailure of the same kind carrying its line). A rank that failed while its
    partners do not join within collective.FAIL_WAIT seconds (they are blocked in a collective call it left)
    ends the whole sweep: ``folders`` get the status, one line, MPI_Abort with its exit status
    (collective.py's rule, here within one group while the sweep's other groups go on)."""
    if group.size == 1:
        return body()
    from damage_dolfinx.runtime import collective
    agree = group.Dup()  # before the body: a rank that fails inside it can still join
    failure, value = None, None
    try:
        value = body()
    except BaseException as exc:  # noqa: BLE001 - decided by the whole group below
        failure = exc
    mine = None if failure is None else \
        (group.rank, *collective.classify(failure)[:2], collective.describe(failure))
    request = agree.Ibarrier()
    deadline = time.monotonic() + collective.FAIL_WAIT
    while not request.Test():
        if failure is not None and time.monotonic() > deadline:
            collective._abort(comm, failure, folders)
        time.sleep(0.002)
    outcomes = agree.allgather(mine)
    agree.Free()
    failed = [o for o in outcomes if o is not None]
    if not failed:
        return value
    if failure is not None:
        raise failure
    _, code, kind, text = failed[0]
    raise collective.decided(text, code, kind)


class Relay:
    """Progress lines of the groups' first ranks, printed by rank 0 alone (only rank 0
    prints): rank 0 prints its own at once and the others' as they arrive, between its points
    and at the end."""

    TAG = 4242

    def __init__(self, comm):
        self.comm = comm.Dup() if comm.size > 1 else comm
        self.sent, self.received, self.requests = 0, 0, []

    def say(self, text):
        if self.comm.rank == 0:
            self._drain()
            print(text, flush=True)
        else:
            self.requests.append(self.comm.isend(text, dest=0, tag=self.TAG))
            self.sent += 1

    def _drain(self):
        status = MPI.Status()
        while self.comm.size > 1 and self.comm.iprobe(source=MPI.ANY_SOURCE, tag=self.TAG,
                                                      status=status):
            print(self.comm.recv(source=status.Get_source(), tag=self.TAG), flush=True)
            self.received += 1

    def close(self):
        """Collective: every line sent is printed before the summary line."""
        if self.comm.size == 1:
            return
        counts = self.comm.gather(self.sent, root=0)
        if self.comm.rank == 0:
            for _ in range(sum(counts) - self.received):
                print(self.comm.recv(source=MPI.ANY_SOURCE, tag=self.TAG), flush=True)
        MPI.Request.Waitall(self.requests)
        self.comm.Free()
