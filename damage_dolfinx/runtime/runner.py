"""The time loop of a catalogue run: progress, incremental output, summary.json.

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

import math
import signal
import sys
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from damage_dolfinx.runtime import checkpoint, io
from damage_dolfinx.catalogue import examples
from damage_dolfinx.numerics.damage import fast_path_counts
from damage_dolfinx.parameters import InputError
from damage_dolfinx.runtime.runfolder import (RunLock, add_to_manifest, check_mesh_file,
                                              claim_folder, previous_run)
from damage_dolfinx.runtime.signals import STOP_SIGNALS, RunInterrupted, StopSignals  # noqa: F401 (cli.py)
from damage_dolfinx.numerics.solvers import ConvergenceError


from damage_dolfinx.runtime.guards import (PDE_STATE_MARGIN, STATE_TOLERANCE,  # noqa: F401
                                           Progress, solver_step, state_problem)
from damage_dolfinx.runtime.figures import auto_amplification, draw_figure  # noqa: F401

#: default wall-time interval between checkpoints (seconds)
CHECKPOINT_SECONDS = 120.0
def run(example_id, out, n=None, k=None, T=None, h=None, overrides=None, mesh_file=None,
        write_every=None, progress=True, figures=True, time_limit=None, checkpoint_every=None,
        checkpoint_seconds=CHECKPOINT_SECONDS, restart=False, overwrite=True,
        history_every=None, comm=MPI.COMM_WORLD) -> dict:
    """Run one catalogue example and write its outputs to ``out``; returns the summary.
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
    ex = resolve(example_id, overrides)
    configured = ex.configure(n, k, T, h, overrides, mesh_file)
    every = history_every if history_every is not None else \
        configured[0].extra.get("history_every", 1)
    if isinstance(every, bool) or not isinstance(every, (int, float)) or every != int(every) \
            or every < 1:
        raise InputError(f"history_every must be a whole number >= 1, got {every!r}")
    every = int(every)
    for name, value in (("--write-every", write_every), ("--checkpoint-every", checkpoint_every)):
        if value is not None and (isinstance(value, bool) or not isinstance(value, int)
                                  or value < 1):
            raise InputError(f"{name} must be a whole number >= 1, got {value!r}")
    if not (isinstance(checkpoint_seconds, (int, float)) and checkpoint_seconds >= 0
            and math.isfinite(checkpoint_seconds)):
        raise InputError(f"--checkpoint-seconds must be a finite number >= 0 (0: none), got "
                         f"{checkpoint_seconds!r}")
    if mesh_file is not None:
        check_mesh_file(mesh_file, ex.dim, lambda: ex.mesh_requirements()[1], comm=comm)
    if restart and not Path(out).is_dir():
        raise InputError(f"cannot restart: no checkpoint in {str(out)!r} (no such folder)")
    out = io.prepare_output_dir(out, comm)
    lock = RunLock(out, comm)
    try:
        with StopSignals() as signals:
            return _run(ex, configured, out, n, k, T, h, overrides, write_every, progress,
                        figures, time_limit, checkpoint_every, checkpoint_seconds, restart,
                        overwrite, comm, signals, lock, every)
    finally:
        lock.release()


def resolve(case, overrides=None):
    """A catalogue id, a public Problem or an Example -> the Example to run."""
    if isinstance(case, str):
        return examples.get(case, (overrides or {}).get("reading"))
    if hasattr(case, "example"):
        return case.example()
    return case


def _run(ex, configured, out, n, k, T, h, overrides, write_every, progress, figures, time_limit,
         checkpoint_every, checkpoint_seconds, restart, overwrite, comm, signals, lock,
         history_every=1) -> dict:
    wall_start = time.perf_counter()
    params, grid, n, h, mesh_file = configured
    settings = {"example": ex.id, "n": n, "h": h, "k": grid.k, "overrides": overrides or {},
                "mesh_file": str(mesh_file) if mesh_file else None}
    if ex.own:  # an own problem: a restart must continue the same model and data
        settings.update(model=ex.model, parameters=params.as_dict())
    previous = previous_run(out, comm)
    resume = None
    if restart:
        resume = checkpoint.resume_point(out, settings, grid, previous, comm,
                                         parameters=params.as_dict())
        if resume is None:
            if comm.rank == 0:
                print(f"damage-dolfinx: nothing to do: the run in {str(out)!r} ended "
                      f"({previous['status']}) at t = {previous['t_final']:.6g} after "
                      f"{previous['steps_done']} steps; its outputs are unchanged"
                      + (" (a larger --T continues it)" if previous["status"] == "completed"
                         else ""), flush=True)
            return previous
    xdmf_name = f"fields_from_step{resume[1]['step']}.xdmf" if resume else "fields.xdmf"
    planned = {"summary.json", "history.csv", xdmf_name, xdmf_name[:-5] + ".h5",
               xdmf_name + ".bak", "fields_final.npz", "checkpoint.json",
               *checkpoint.GENERATIONS, *(fig.filename for fig in ex.figures if figures)}
    description = previous["description"] if previous else None
    claim_folder(out, "run", planned, restart, overwrite, comm, description, apply=False)
    path, resume = resume or (None, None)
    if resume:
        repaired = comm.bcast(io.repair_xdmf(out) if comm.rank == 0 else None)
        if repaired and comm.rank == 0:
            print(f"damage-dolfinx: {', '.join(repaired)} restored to its last complete output "
                  "time (the run was killed while writing it)", file=sys.stderr, flush=True)
    try:  # before any step: a solver that cannot be set up is refused input (PETSc options)
        stepper = solver_step(lambda: ex.build(comm, n, k, T, h, overrides, mesh_file),
                              "cannot set up the solvers")
    except ConvergenceError as exc:
        raise InputError(str(exc)) from None
    settings["fingerprint"] = checkpoint.verify_fingerprint(ex, stepper, resume, out)
    claim_folder(out, "run", planned, restart, overwrite, comm, description)
    if (resume or checkpoint_every) and not stepper.checkpoint_supported:
        raise InputError(f"example {ex.id} does not support checkpoints")
    supported = stepper.checkpoint_supported
    try:
        if supported:
            stepper.checkpoint_state()
    except InputError:  # a variant without checkpoints (2.3 memory_mode=sum)
        if resume or checkpoint_every:
            raise
        supported = False
    N = stepper.num_steps
    write_every = write_every or max(1, N // 20)
    checkpoints = supported and bool(checkpoint_every or checkpoint_seconds)

    summary = {"schema": "damage-dolfinx/summary/v1", "example": ex.id, "title": ex.title,
               "section": ex.section, "status": "running", "parameters": params.as_dict(),
               "n": n, "h": stepper.data.geometry.h, "k": grid.k, "T": grid.T, "num_steps": N,
               "history_every": history_every,
               "steps_done": 0, "t_final": 0.0, "mpi_size": comm.size,
               "mesh": stepper.mesh_info(), "assumptions": ex.assumptions,
               "outputs": {"xdmf": "fields.xdmf", "history": "history.csv",
                           "final_fields": "fields_final.npz", "figures": []},
               "environment": io.environment(comm)}
    summary["outputs"]["xdmf"] = xdmf_name
    files = {}  # the XDMF series and the history, created below (collectively checked)
    columns = ["step", "t", "u_L2", "eps_u_L2", "zeta_min", "zeta_max", "zeta_mean",
               "damage_its", "mech_its", "snes_its", "step_time_s", *stepper.extra_history_columns]

    def open_files():
        files["xdmf"] = io.XDMFSeries(out / xdmf_name, stepper.mesh)
        files["history"] = io.CSVHistory(out / "history.csv", columns, comm,
                                         keep_until_step=resume["step"] if resume else None)
    io.collective(comm, out, f"{xdmf_name} / history.csv (opening)", open_files)
    xdmf, history = files["xdmf"], files["history"]
    report = Progress(ex.id, N, comm, enabled=progress)
    # steppers without track() compute their scalars (whatever they keep track of stays right)
    track = getattr(stepper, "track", None) or stepper.scalars
    previous_wall = resume["wall_time_s"] if resume else 0.0
    if resume:
        summary["restarts"] = resume.get("restarts", []) + [
            {"step": resume["step"], "mpi_size": comm.size, "previous_mpi_size": resume["mpi_size"]}]
    last_checkpoint = {"time": time.perf_counter(), "step": resume["step"] if resume else None}

    def at(name):
        return f"{name} at step {stepper.n} (t = {stepper.t:.6g})"

    def write_summary():
        io.collective(comm, out, at("summary.json"), io.write_json, out / "summary.json",
                      summary, comm)

    def save_checkpoint():
        write_summary()  # first: the summary is never behind the checkpoint
        checkpoint.save(out, stepper.checkpoint_state(), {
            **settings, "parameters": summary["parameters"], "step": stepper.n,
            "t": stepper.t, "mpi_size": comm.size,
            "wall_time_s": previous_wall + time.perf_counter() - wall_start,
            "restarts": summary.get("restarts", [])}, comm)
        last_checkpoint.update(time=time.perf_counter(), step=stepper.n)

    def end_of_step():
        """One allreduce per step: seconds since the last checkpoint and since the start, the
        signal received (if any) and whether the history row failed, agreed by all ranks."""
        now = time.perf_counter()
        bad, detail = state_problem(stepper)
        state = np.array([now - last_checkpoint["time"], now - wall_start, signals.signum,
                          float(history.error is not None), bad])
        comm.Allreduce(MPI.IN_PLACE, state, op=MPI.MAX)
        if state[3]:
            reason = comm.bcast(io.describe(history.error, out) if comm.rank == 0 else None)
            raise io.OutputError(f"cannot write {at('history.csv')}: {reason}")
        if state[4]:
            check_state()  # raises (the detail from a rank that has it)
        return state[0], state[1], int(state[2])

    def check_state():
        """Stop on a NaN/Inf or a zeta outside [zeta_star, 1] on any rank (collective)."""
        bad, detail = state_problem(stepper)
        ranks = comm.allgather(detail if bad else None)
        detail = next((d for d in ranks if d), None)
        if detail:
            raise ConvergenceError(f"{at('the state')}: {detail}; the run is stopped (the "
                                   "model or its data gave numbers that cannot be right)")

    def checkpoint_due(since_checkpoint) -> bool:
        if not supported:
            return False
        if checkpoint_every:
            return stepper.n % checkpoint_every == 0
        return bool(checkpoint_seconds) and since_checkpoint > checkpoint_seconds

    recorded = {"step": None}

    def record(stats, step_time, row=True):
        """The step's scalars into the summary and (``row``) a history.csv row."""
        scalars = stepper.scalars()
        if row:
            history.write({"step": stepper.n, "t": stepper.t, **scalars, **stats,
                           "step_time_s": f"{step_time:.4g}"})
        recorded["step"] = stepper.n
        summary.update(steps_done=stepper.n, t_final=stepper.t, final=scalars,
                       iterations={**stepper.iteration_totals(), **fast_path_counts(stepper)},
                       wall_time_s=previous_wall + time.perf_counter() - wall_start,
                       **stepper.summary_extra())
        return scalars

    def up_to_date(stats, step_time):
        """The summary of the current step (a step between history rows has none yet)."""
        if recorded["step"] != stepper.n:
            record(stats, step_time, row=False)

    def write_fields():
        stepper.update_output()
        io.collective(comm, out, at(f"{xdmf_name} (+ .h5)"), xdmf.write, stepper.output_fields,
                      stepper.t)
        write_summary()

    def figure(fig, suffix=""):
        def draw():
            add_to_manifest(out, [fig.filename.replace(".png", f"{suffix}.png")], comm)
            summary["outputs"]["figures"].append(draw_figure(ex, fig, stepper, out, suffix))
        io.collective(comm, out, at(fig.filename), draw)

    def timed_figures():
        """Figures requested at the current time (Figure.times)."""
        for fig in ex.figures if figures else []:
            if any(abs(stepper.t - t) < 0.5 * grid.k for t in fig.times):
                stepper.update_output()
                figure(fig, suffix=f"_t{stepper.t:g}")

    def interrupt(signum):
        name = signal.Signals(signum).name
        if supported:
            save_checkpoint()
        summary.update(status="interrupted", signal=name,
                       wall_time_s=previous_wall + time.perf_counter() - wall_start)
        write_summary()
        kept = ("checkpoint written; --restart continues the run" if supported
                else f"example {ex.id} has no checkpoints: the history and fields so far stay")
        raise RunInterrupted(signum, f"stopped by {name} after step {stepper.n} "
                                     f"(t = {stepper.t:.6g}): {kept}")

    try:
        start = time.perf_counter()
        if resume:
            checkpoint.load(path, stepper.checkpoint_state())
            stepper.restore(resume["step"])
            check_state()
            stats = {}
            scalars = record(stats, 0.0, row=False)  # the summary from the state on disk
            write_fields()
        else:
            stats = solver_step(stepper.initialize, at("the initial solve"))
            check_state()
            scalars = record(stats, time.perf_counter() - start)
            write_fields()
            timed_figures()
        report(stepper.n, stepper.t, stats, scalars, force=True)
        stop = None
        while stepper.n < N:
            start = time.perf_counter()
            stats = solver_step(stepper.advance, f"step {stepper.n + 1} (t = "
                                                 f"{stepper.t + grid.k:.6g})")
            step_time = time.perf_counter() - start
            row = stepper.n % history_every == 0 or stepper.n == N
            if row:
                scalars = record(stats, step_time)
            else:  # between history rows: only the extremes over all steps
                track()
                scalars = stepper.scalars
            since_checkpoint, elapsed, signum = end_of_step()
            if signum and stepper.n < N:
                up_to_date(stats, step_time)
                interrupt(signum)
            stop = stepper.stop_reason()
            if time_limit and elapsed > time_limit:
                stop = stop or "time_limit"
            if stop and not row:  # the stopping step always has its row
                scalars = record(stats, step_time)
            if stop or stepper.n % write_every == 0 or stepper.n == N:
                up_to_date(stats, step_time)
                write_fields()
            if (stop and stepper.n < N) or checkpoint_due(since_checkpoint):
                up_to_date(stats, step_time)
                save_checkpoint()
            timed_figures()
            report(stepper.n, stepper.t, stats, scalars, force=bool(stop))
            if stop:
                break
        status = stop or "completed"  # recorded last: a kill before the end leaves "running"
        if checkpoints and last_checkpoint["step"] != stepper.n:
            save_checkpoint()  # so that --restart with a larger T continues from here
        history.close()
        stepper.update_output()
        final = {"u": stepper.u, "zeta": stepper.zeta, "von_mises": stepper.von_mises}
        final.update({f.name: f for f in stepper.output_fields if f.name not in final})
        io.collective(comm, out, at("fields_final.npz"), io.save_final_fields,
                      out / "fields_final.npz", final)
        if figures:
            stepper.update_output()
            for fig in ex.figures:
                if not fig.times:
                    figure(fig)
    except (ConvergenceError, io.OutputError) as exc:
        summary.update(status="failed", error=str(exc),
                       wall_time_s=previous_wall + time.perf_counter() - wall_start)
        if comm.rank == 0:
            lock.free_reserve()
            try:  # where space allows (the lock's reserve is freed for it)
                io.write_json(out / "summary.json", summary, comm)
            except OSError:
                pass
        history.close()
        raise
    summary["timings_s"] = dict(getattr(stepper, "timings", {}))
    summary.update(status=status, wall_time_s=previous_wall + time.perf_counter() - wall_start)
    write_summary()
    if comm.rank == 0 and progress:
        print(f"[{ex.id}] {summary['status']} at t = {stepper.t:.5g} after {stepper.n} steps in "
              f"{summary['wall_time_s']:.1f} s on {comm.size} rank(s); output in {out}", flush=True)
    return summary
