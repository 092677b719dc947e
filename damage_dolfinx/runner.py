"""The time loop of a catalogue run: progress, incremental output, summary.json.

``summary.json`` contract (schema ``damage-dolfinx/summary/v1``; later problems add keys, never
remove or rename them):

    schema, example, title, section, status ("running" | "completed" | "zeta_star_reached" |
    "failed"), error (if failed), parameters (all model parameters), n, h, k, T, num_steps
    (planned), steps_done, t_final, mpi_size, wall_time_s, timings_s, iterations (total solver
    iterations: damage_ksp, mech_ksp, snes), mesh (cells, vertices, dofs, h, description),
    final (u_L2, eps_u_L2, zeta_min, zeta_max, zeta_mean at t_final), assumptions, outputs
    (file names), environment (versions, MPI size, command, date).

The file is rewritten at every output time, so an interrupted run leaves a readable summary
with status "running" and the CSV history of every finished step.
"""
from __future__ import annotations

import math
import time
from pathlib import Path

from mpi4py import MPI

from . import checkpoint, examples, io, post
from .parameters import InputError
from .geometries import GAMMA_C, GAMMA_D, GAMMA_N
from .solvers import ConvergenceError


class Progress:
    """Rank-0 progress lines, at most one every ``interval`` seconds (plus first and last)."""

    def __init__(self, label, total, comm, enabled=True, interval=2.0):
        self.label, self.total, self.enabled = label, total, enabled and comm.rank == 0
        self.interval, self.start, self.last = interval, time.perf_counter(), -math.inf

    def __call__(self, step, t, stats, scalars, force=False):
        now = time.perf_counter()
        if not self.enabled or (not force and now - self.last < self.interval and step != self.total):
            return
        self.last = now
        elapsed = now - self.start
        eta = elapsed / max(step, 1) * (self.total - step)
        its = " ".join(f"{k}={v}" for k, v in stats.items())
        print(f"[{self.label}] step {step}/{self.total} t={t:.5g} {its} "
              f"min zeta={scalars['zeta_min']:.4f} ({elapsed:.1f} s, ETA {eta:.0f} s)", flush=True)


#: default wall-time interval between checkpoints (seconds)
CHECKPOINT_SECONDS = 120.0


def run(example_id, out, n=None, k=None, T=None, h=None, overrides=None, mesh_file=None,
        write_every=None, progress=True, figures=True, time_limit=None, checkpoint_every=None,
        checkpoint_seconds=CHECKPOINT_SECONDS, restart=False, comm=MPI.COMM_WORLD) -> dict:
    """Run one catalogue example and write its outputs to ``out``; returns the summary.
    With ``time_limit`` (seconds) the run stops after the step that exceeds it, with status
    "time_limit" (used by benchmarks that skip cells a solver cannot finish).

    Checkpoints (checkpoint.py) are written every ``checkpoint_every`` steps, or else every
    ``checkpoint_seconds`` of wall time (0: never), and when the run stops early; ``restart``
    resumes from the checkpoint in ``out`` (same example, mesh, k and parameters; any number
    of ranks; T may be larger), keeping the history rows up to the checkpoint."""
    wall_start = time.perf_counter()
    ex = examples.get(example_id)
    params, grid, n, h, mesh_file = ex.configure(n, k, T, h, overrides, mesh_file)
    settings = {"example": ex.id, "n": n, "h": h, "k": grid.k, "overrides": overrides or {},
                "mesh_file": str(mesh_file) if mesh_file else None}
    resume = _check_restart(out, settings, grid) if restart else None
    out = io.prepare_output_dir(out, comm)
    stepper = ex.build(comm, n, k, T, h, overrides, mesh_file)
    if (resume or checkpoint_every) and not stepper.checkpoint_supported:
        raise InputError(f"example {ex.id} does not support checkpoints")
    N = stepper.num_steps
    write_every = write_every or max(1, N // 20)

    summary = {"schema": "damage-dolfinx/summary/v1", "example": ex.id, "title": ex.title,
               "section": ex.section, "status": "running", "parameters": params.as_dict(),
               "n": n, "h": stepper.data.geometry.h, "k": grid.k, "T": grid.T, "num_steps": N,
               "steps_done": 0, "t_final": 0.0, "mpi_size": comm.size,
               "mesh": stepper.mesh_info(), "assumptions": ex.assumptions,
               "outputs": {"xdmf": "fields.xdmf", "history": "history.csv",
                           "final_fields": "fields_final.npz", "figures": []},
               "environment": io.environment(comm)}
    xdmf_name = f"fields_from_step{resume['step']}.xdmf" if resume else "fields.xdmf"
    summary["outputs"]["xdmf"] = xdmf_name
    xdmf = io.XDMFSeries(out / xdmf_name, stepper.mesh)
    history = io.CSVHistory(out / "history.csv",
                            ["step", "t", "u_L2", "eps_u_L2", "zeta_min", "zeta_max", "zeta_mean",
                             "damage_its", "mech_its", "snes_its", "step_time_s",
                             *stepper.extra_history_columns], comm,
                            keep_until_step=resume["step"] if resume else None)
    report = Progress(ex.id, N, comm, enabled=progress)
    previous_wall = resume["wall_time_s"] if resume else 0.0
    if resume:
        summary["restarts"] = resume.get("restarts", []) + [
            {"step": resume["step"], "mpi_size": comm.size, "previous_mpi_size": resume["mpi_size"]}]
    last_checkpoint = [time.perf_counter()]

    def save_checkpoint():
        checkpoint.save(out, stepper.checkpoint_state(), {
            **settings, "step": stepper.n, "t": stepper.t, "mpi_size": comm.size,
            "wall_time_s": previous_wall + time.perf_counter() - wall_start,
            "restarts": summary.get("restarts", [])}, comm)
        last_checkpoint[0] = time.perf_counter()

    def checkpoint_due() -> bool:
        if not stepper.checkpoint_supported:
            return False
        if checkpoint_every:
            return stepper.n % checkpoint_every == 0
        elapsed = comm.allreduce(time.perf_counter() - last_checkpoint[0], op=MPI.MAX)
        return bool(checkpoint_seconds) and elapsed > checkpoint_seconds

    def record(stats, step_time):
        scalars = stepper.scalars()
        history.write({"step": stepper.n, "t": stepper.t, **scalars, **stats,
                       "step_time_s": f"{step_time:.4g}"})
        summary.update(steps_done=stepper.n, t_final=stepper.t, final=scalars,
                       iterations=stepper.iteration_totals(),
                       wall_time_s=previous_wall + time.perf_counter() - wall_start,
                       **stepper.summary_extra())
        return scalars

    def write_fields():
        stepper.update_output()
        xdmf.write(stepper.output_fields, stepper.t)
        io.write_json(out / "summary.json", summary, comm)

    def timed_figures():
        """Figures requested at the current time (Figure.times)."""
        for fig in ex.figures if figures else []:
            if any(abs(stepper.t - t) < 0.5 * grid.k for t in fig.times):
                stepper.update_output()
                summary["outputs"]["figures"].append(
                    draw_figure(ex, fig, stepper, out, suffix=f"_t{stepper.t:g}"))

    try:
        start = time.perf_counter()
        if resume:
            checkpoint.load(out, stepper.checkpoint_state())
            stepper.restore(resume["step"])
            stats, scalars = {}, stepper.scalars()
            write_fields()
        else:
            stats = stepper.initialize()
            scalars = record(stats, time.perf_counter() - start)
            write_fields()
            timed_figures()
        report(stepper.n, stepper.t, stats, scalars, force=True)
        while stepper.n < N:
            start = time.perf_counter()
            stats = stepper.advance()
            scalars = record(stats, time.perf_counter() - start)
            stop = stepper.stop_reason()
            if time_limit and comm.allreduce(time.perf_counter() - wall_start, op=MPI.MAX) > time_limit:
                stop = stop or "time_limit"
            if stop or stepper.n % write_every == 0 or stepper.n == N:
                write_fields()
            if (stop and stepper.n < N) or checkpoint_due():
                save_checkpoint()
            timed_figures()
            report(stepper.n, stepper.t, stats, scalars, force=bool(stop))
            if stop:
                summary["status"] = stop
                break
        else:
            summary["status"] = "completed"
    except ConvergenceError as exc:
        summary.update(status="failed", error=str(exc),
                       wall_time_s=previous_wall + time.perf_counter() - wall_start)
        io.write_json(out / "summary.json", summary, comm)
        history.close()
        raise
    history.close()
    stepper.update_output()
    final = {"u": stepper.u, "zeta": stepper.zeta, "von_mises": stepper.von_mises}
    final.update({f.name: f for f in stepper.output_fields if f.name not in final})
    io.save_final_fields(out / "fields_final.npz", final)
    if figures:
        stepper.update_output()
        summary["outputs"]["figures"] += [draw_figure(ex, fig, stepper, out)
                                          for fig in ex.figures if not fig.times]
    summary["timings_s"] = dict(getattr(stepper, "timings", {}))
    summary["wall_time_s"] = previous_wall + time.perf_counter() - wall_start
    io.write_json(out / "summary.json", summary, comm)
    if comm.rank == 0 and progress:
        print(f"[{ex.id}] {summary['status']} at t = {stepper.t:.5g} after {stepper.n} steps in "
              f"{summary['wall_time_s']:.1f} s on {comm.size} rank(s); output in {out}", flush=True)
    return summary


def _check_restart(out, settings, grid) -> dict:
    """The checkpoint metadata in ``out`` after checking it belongs to this run."""
    meta = checkpoint.read_meta(out)
    for key, value in settings.items():
        if meta.get(key) != value:
            raise InputError(f"cannot restart: the checkpoint in {str(out)!r} has {key} = "
                             f"{meta.get(key)!r}, this run {value!r}")
    if meta["step"] > grid.num_steps:
        raise InputError(f"cannot restart: the checkpoint is at t = {meta['t']}, beyond T = {grid.T}")
    return meta


def auto_amplification(stepper, diameter) -> float:
    """G40: the factor that makes the largest displacement 10% of the domain diameter."""
    import numpy as np
    u = stepper.u.x.array.reshape(-1, 2)
    umax = stepper.comm.allreduce(float(np.max(np.linalg.norm(u, axis=1))) if u.size else 0.0,
                                  op=MPI.MAX)
    return 0.1 * diameter / umax if umax > 0 else 1.0


def draw_figure(ex, fig, stepper, out: Path, suffix="") -> dict:
    """One catalogue figure (PNG) of the current state; returns its file entry."""
    filename = fig.filename.replace(".png", f"{suffix}.png")
    if fig.kind == "history":  # history.csv is complete and flushed at the end of the run
        if stepper.comm.rank == 0:
            post.plot_history(out / "history.csv", fig.fields, out / filename, title=fig.title)
        return {"file": filename}
    if fig.kind == "profiles":  # damage along a line at several times + probe history
        if stepper.comm.rank == 0:
            post.plot_damage_profiles(stepper.summary_extra()["profiles"], out / "history.csv",
                                      stepper.params.zeta_star, out / filename, fig.title)
        return {"file": filename}
    if fig.kind == "mesh":
        post.plot_mesh(stepper.data.geometry, out / filename, title=fig.title,
                       labels={GAMMA_D: "Gamma_D (clamped)", GAMMA_N: "Gamma_N (loaded/free)",
                               GAMMA_C: "Gamma_C (contact)"})
        return {"file": filename}
    fields = {"von_mises": (stepper.von_mises, "von Mises stress [Pa]"),
              "zeta": (stepper.zeta, "damage zeta [-]")}
    fields.update(getattr(stepper, "figure_fields", {}))  # problem-specific (name: (Function, label))
    amp = fig.amplification or auto_amplification(stepper, ex.diameter)
    post.plot_fields(stepper.u, [fields[f] for f in fig.fields], out / filename,
                     amplification=amp, title=f"{fig.title} (t = {stepper.t:.4g})", outline=True,
                     mesh_lines=fig.mesh_lines)
    return {"file": filename, "t": stepper.t, "amplification": amp}
