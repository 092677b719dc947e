"""The generic time loop of a run (any model): progress, incremental output, summary.json.

:func:`run` drives :class:`Run`, whose :meth:`Run.steps` yields a :class:`Step` (the time, the
step and the live Functions) after the initial state and after every step; a caller that stops
iterating ends the run there, with its outputs and a checkpoint (status "stopped").

``summary.json`` contract (schema ``damage-dolfinx/summary/v1``; later problems add keys, never
remove or rename them):

    schema, example, title, section, status ("running" | "completed" | "zeta_star_reached" |
    "failed" | "interrupted"), error (if failed), signal (if interrupted), parameters (all model
    parameters), n, h, k, T, num_steps (planned), history_every (a history.csv row every that
    many steps), steps_done, t_final, mpi_size, wall_time_s, timings_s, iterations (total solver
    iterations: damage_ksp, mech_ksp, snes), mesh (cells, vertices, dofs, h, description), final
    (u_L2, eps_u_L2, zeta_min, zeta_max, zeta_mean at t_final), assumptions, outputs (file
    names), environment (versions, MPI size, command, date).

The file is rewritten (atomically) at every output time, so a killed run leaves a readable
summary with status "running" and the CSV history of every finished step. Faults (README,
Command line): a full disk or another output error stops the run with io.OutputError after
marking the summary "failed" where space allows; SIGTERM/SIGINT/SIGUSR1 stop it at the end of
the step with a checkpoint and status "interrupted" (RunInterrupted, signals.py);
runfolder.RunLock refuses a second run into a folder where one is live.
"""
from __future__ import annotations

from mpi4py import MPI

# names other modules take from here (the command line, the studies, the figures' tests)
from damage_dolfinx.runtime.cases import resolve  # noqa: F401
from damage_dolfinx.runtime.figures import auto_amplification, draw_figure  # noqa: F401
from damage_dolfinx.runtime.guards import (PDE_STATE_MARGIN, STATE_TOLERANCE,  # noqa: F401
                                           Progress, solver_step)
from damage_dolfinx.runtime.records import ColumnError  # noqa: F401
from damage_dolfinx.runtime.signals import STOP_SIGNALS, RunInterrupted  # noqa: F401
from damage_dolfinx.runtime.step import CHECKPOINT_SECONDS, Step  # noqa: F401


def run(example_id, out, n=None, k=None, T=None, h=None, overrides=None, mesh_file=None,
        write_every=None, progress=True, figures=True, time_limit=None, checkpoint_every=None,
        checkpoint_seconds=CHECKPOINT_SECONDS, restart=False, overwrite=True,
        history_every=None, comm=MPI.COMM_WORLD, on_step=None) -> dict:
    """Run one case (a run description, a Problem or a registered name) and write its outputs
    to ``out``; returns the summary. ``on_step(step)`` (a :class:`Step`) is called after the
    initial state and after every step; a true return value (on any rank) stops every rank
    there, an exception (on any rank) ends every rank with the status "failed": the ranks
    decide together after each call (runtime/callbacks.py).
    With ``time_limit`` (seconds) the run stops after the step that exceeds it, with status
    "time_limit" (used by benchmarks that skip cells a solver cannot finish).

    Checkpoints (checkpoint.py) are written every ``checkpoint_every`` steps, or else every
    ``checkpoint_seconds`` of wall time (0 and no ``checkpoint_every``: never), when the run
    stops early or on a signal, and at its end; ``restart`` resumes from the checkpoint in
    ``out`` (same example, mesh, k and parameters; any number of ranks; a larger T continues a
    completed run, otherwise a finished run is left as it is), keeping the history rows up to
    the checkpoint. A folder holding a run is refused (InputError) unless ``restart`` or
    ``overwrite`` (the command line passes overwrite=False unless --overwrite); a folder where a
    run is live is always refused (runfolder.RunLock). Output errors raise io.OutputError, signals
    RunInterrupted, both after recording the status in summary.json.

    History cadence: ``history_every`` (default: the example's parameter
    ``history_every``, else 1) writes a history.csv row every that many steps, plus the first,
    the last and a stopping step. In between, the stepper only updates what summary.json reports
    over all steps (``stepper.track()``: the 3.3 maximal interpenetration, its time and place;
    a stepper without it computes its scalars), and the summary's other scalars are brought up
    to date before each output, checkpoint or stop.

    Refused before any work (InputError): cadences below 1, a ``mesh_file`` that is not a readable mesh of the example's dimension
    with its boundary tags (runfolder.check_mesh_file), and a folder the run may not write
    into (runfolder.claim_folder: the manifest). A NaN, an infinity or a zeta outside
    [zeta_star, 1] (beyond STATE_TOLERANCE) in a field, and every exception of a solver, end
    the run as a ConvergenceError with status "failed" in summary.json."""
    from damage_dolfinx.runtime.callbacks import decide
    from damage_dolfinx.runtime.loop import Run  # imported when a run starts (dolfinx)
    r = Run.prepare(example_id, out, n, k, T, h, overrides, mesh_file, write_every, progress,
                    figures, time_limit, checkpoint_every, checkpoint_seconds, restart,
                    overwrite, history_every, comm)
    steps = r.steps()
    try:
        for step in steps:  # on_step: decided on every rank alike (runtime/callbacks.py)
            if on_step is not None and decide(r.comm, on_step, step, step=step.n):
                steps.close()
    except BaseException:  # on_step raised (the run's own failures have ended the loop)
        r.abandon(steps)
        raise
    return r.summary
