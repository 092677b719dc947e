"""Command line: ``damage-dolfinx list | run ID | converge ID | sweep ID`` (works unchanged under
mpirun).

Single-dash options are PETSc options of the package's solvers (``-mech_ksp_type cg``,
``-damage_snes_monitor``; prefixes PETSC_PREFIXES): any other single-dash word is refused with
the double-dash option it resembles, a value PETSc refuses is refused before any work, and an
option no solver read is named in a warning at the end. User errors print one line on rank 0
and exit with status 2; a solver
that does not converge or fails, or a state that is not finite or leaves [zeta_star, 1], exits
with status 3 after writing what was finished (summary.json "failed"); an output error
(disk full, I/O error, output folder deleted) exits with status 4; SIGTERM, SIGINT or SIGUSR1
stop a run at the end of the current step with a checkpoint, exit status 128 + signal number
(143, 130, 138); a repeat of the signal within 5 s is ignored, a later one ends the process
at once (signals.StopSignals). Outside a run's time loop (set-up, a convergence study, a sweep
between points) SIGTERM and SIGINT stop the command with one line, the status recorded and the
same exit status. Any other exception (the user's own code) is one line, exit status 3. Under
MPI every rank ends with the same status, also when only one rank failed
(runtime/collective.py).
"""
from __future__ import annotations

import os
import signal as _signal
import sys

#: a stop signal that came while the command was starting (before main() set its handlers):
#: main() then stops at once with the one line and the exit status 128 + signal
_EARLY = []


def _early(signum, frame):
    _EARLY.append(signum)


#: started as the command (python -m damage_dolfinx.cli, the damage-dolfinx script), not
#: imported by a program of its own (whose signal handlers stay as they are)
_AS_COMMAND = sys.argv[:1] == ["-m"] or os.path.basename(sys.argv[0] if sys.argv else "") in (
    "damage-dolfinx", "__main__.py")
try:  # from the first moment: no stop signal kills the command without a line
    for _s in (_signal.SIGTERM, _signal.SIGINT, _signal.SIGUSR1) if _AS_COMMAND else ():
        if _signal.getsignal(_s) in (_signal.SIG_DFL, _signal.default_int_handler):
            _signal.signal(_s, _early)
except ValueError:  # not the main thread
    pass

#: set by an MPI launcher (Open MPI's mpirun, PMIx, PMI: MPICH's hydra, Slurm's srun) in the
#: environment of the processes it starts
_LAUNCHER_VARIABLES = ("OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE")
#: Open MPI's settings of a process alone: shared memory and TCP only, the pml without UCX
#: (the values the Makefile gives the tests and demos), and no supporting daemon (orted: a
#: singleton then cannot spawn processes, which the package never does)
_SINGLETON_SETTINGS = {"OMPI_MCA_btl": "^ofi,uct", "OMPI_MCA_pml": "ob1",
                       "OMPI_MCA_ess_singleton_isolated": "1"}


def _start_mpi():
    """MPI_Init (the import of mpi4py.MPI). A command that no MPI launcher started is one rank
    alone and talks to no other process, yet Open MPI starts a daemon for it and probes every
    network transport, which makes MPI_Init several times slower than it needs to be
    (benchmarks/README.md, "Why the defaults"). Such a process starts with _SINGLETON_SETTINGS,
    for MPI_Init only: a value
    set outside is kept, and the variables are taken out again (a process it starts does not
    inherit them). Other MPI libraries ignore them."""
    added = {} if any(v in os.environ for v in _LAUNCHER_VARIABLES) else \
        {k: v for k, v in _SINGLETON_SETTINGS.items() if k not in os.environ}
    os.environ.update(added)
    try:
        from mpi4py import MPI  # noqa: F401  (MPI_Init)
    finally:
        for key in added:
            os.environ.pop(key, None)


_start_mpi()
from mpi4py import MPI  # noqa: E402

# the parts, by concept: the arguments (arguments.py), the PETSc options among them
# (petsc_options.py), what each command does (commands.py); these names are their public face
from damage_dolfinx.cli.commands import command  # noqa: E402
from damage_dolfinx.cli.arguments import _overrides, _parser  # noqa: F401,E402
from damage_dolfinx.problem.petsc_options import (PETSC_GLOBAL, PETSC_PREFIXES,  # noqa: F401,E402
                                              _check_petsc_values, _forget, _petsc_options,
                                              _unused)


def main(argv=None):
    """The command; every rank returns the same exit status (runtime/collective.py: an
    exception on one rank only becomes one decided outcome, or ends the job)."""
    import signal
    from damage_dolfinx.runtime.signals import stop_outside_runs
    comm = MPI.COMM_WORLD
    given = {}
    before = {}
    try:
        for s in (signal.SIGTERM, signal.SIGINT, signal.SIGUSR1):  # the run's loop has its own
            before[s] = signal.signal(s, stop_outside_runs)        # (StopSignals)
    except ValueError:  # not the main thread
        pass
    try:
        return _main(argv, comm, given)
    finally:
        from damage_dolfinx.runtime.signals import taken
        taken()
        for s, handler in before.items():
            if signal.getsignal(s) is stop_outside_runs:  # (an interruption leaves SIG_IGN)
                signal.signal(s, handler)
        if _AS_COMMAND:  # the command has ended, its status written: a stop signal now (while
            try:         # Python, MPI and PETSc shut down, which put back the default
                for s in (signal.SIGTERM, signal.SIGINT, signal.SIGUSR1):  # actions) changes
                    signal.signal(s, signal.SIG_IGN)                         # nothing
            except (ValueError, OSError):
                pass


def _main(argv, comm, given):
    from damage_dolfinx.runtime import collective
    from damage_dolfinx.runtime.atomic import OutputError  # (runtime.io would load dolfinx)
    from damage_dolfinx.runtime.signals import RunInterrupted
    try:
        with collective.outcome(comm):
            try:
                if _EARLY:  # a stop signal while the command was starting
                    from damage_dolfinx.runtime.signals import RECEIVED, SignalStop
                    RECEIVED["signum"] = RECEIVED["signum"] or _EARLY[0]
                    raise SignalStop(_EARLY.pop(0))
                return command(argv, comm, given)
            finally:
                _forget(given)
    except OutputError as exc:
        _say(comm, collective.line(exc))
        from damage_dolfinx.runtime.io import FAILED_HDF5_FILES
        if FAILED_HDF5_FILES:  # HDF5 would crash shutting down the failed file
            sys.stdout.flush()
            comm.Barrier()
            os._exit(4)
        return 4
    except (RunInterrupted, KeyboardInterrupt, collective.RankFailure) as exc:
        import signal
        from damage_dolfinx.runtime.signals import taken
        taken()
        from damage_dolfinx.runtime.signals import STOP_SIGNALS
        if not isinstance(exc, collective.RankFailure) or exc.kind == "":
            for s in STOP_SIGNALS:  # the request arriving twice must not kill us on the way out
                signal.signal(s, signal.SIG_IGN)
        _say(comm, collective.line(exc))
        return collective.classify(exc)[0]
    except Exception as exc:  # noqa: BLE001 - input, solver, user code: one line, its status
        _say(comm, collective.line(exc))
        return collective.classify(exc)[0]


def _say(comm, text):
    if comm.rank == 0:
        from damage_dolfinx.cli.wording import for_command_line
        print(for_command_line(text), file=sys.stderr, flush=True)
