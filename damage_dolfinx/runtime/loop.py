"""The run loop behind :func:`damage_dolfinx.runtime.runner.run`: :class:`Run` sets a run up
(resume point, folder claim, the model, summary and files), then :meth:`Run.steps` runs the
generic time loop (any model) and yields a :class:`~damage_dolfinx.runtime.runner.Step` after
the initial state and after every step. What a step writes is in records.py."""
from __future__ import annotations

import sys
import time
from pathlib import Path

from mpi4py import MPI

from damage_dolfinx.core import departures
from damage_dolfinx.numerics.contact_output import ContactOutput
from damage_dolfinx.numerics.solvers import ConvergenceError
from damage_dolfinx.core.parameters import InputError
from damage_dolfinx.runtime import checkpoint, io
from damage_dolfinx.runtime.cases import resolve
from damage_dolfinx.runtime.guards import Progress, solver_step
from damage_dolfinx.runtime.records import HISTORY_FIGURE, RunRecords
from damage_dolfinx.runtime.runfolder import (RunLock, check_mesh_file, claim_folder,
                                              previous_run)
from damage_dolfinx.runtime.step import CHECKPOINT_SECONDS, Step
from damage_dolfinx.runtime.signals import StopSignals
from damage_dolfinx.runtime.steps import together

class Run(RunRecords):
    """One run into a folder: set up (:meth:`prepare`), then :meth:`steps`."""

    @classmethod
    def prepare(cls, case, out, n=None, k=None, T=None, h=None, overrides=None, mesh_file=None,
                write_every=None, progress=True, figures=True, time_limit=None,
                checkpoint_every=None, checkpoint_seconds=CHECKPOINT_SECONDS, restart=False,
                overwrite=True, history_every=None, comm=MPI.COMM_WORLD) -> "Run":
        """Everything refused before any work (see :func:`run`)."""
        ex = resolve(case, overrides)
        configured = ex.configure(n, k, T, h, overrides, mesh_file, comm)
        # the arguments were checked by the entry point (core.validation.check_run), the
        # parameter history_every with the data (core.parameters.EXTRA_RULES)
        every = history_every if history_every is not None else \
            configured.params.extra.get("history_every", 1)
        if mesh_file is not None:
            check_mesh_file(mesh_file, ex.dim, lambda: ex.mesh_requirements()[1], comm=comm)
        if restart and not Path(out).is_dir():
            raise InputError(f"cannot restart: no checkpoint in {str(out)!r} (no such folder)")
        r = cls()
        r.ex, r.configured, r.comm = ex, configured, comm
        r.options = dict(n=n, k=k, T=T, h=h, overrides=overrides, write_every=write_every,
                         progress=progress, figures=figures, time_limit=time_limit,
                         checkpoint_every=checkpoint_every,
                         checkpoint_seconds=checkpoint_seconds, restart=restart,
                         overwrite=overwrite, history_every=int(every))
        r.out = io.prepare_output_dir(out, comm)
        r.summary = None
        return r

    #: the caller's code raised inside the loop (Run.abandon): no outputs of a stop
    abandoned = False
    #: the ranks agree after every hand-over whether their callers left the loop (dd.steps
    #: under MPI: runtime/steps.together)
    handshake = False

    def abandon(self, steps, tell=False):
        """End the generator ``steps`` after the caller's own code raised inside the loop: no
        outputs of a stop (a rank alone in this may not enter a collective write while the
        others solve; the exception decides the status, runtime/collective.py). ``tell``: the
        other ranks learn it at their next hand-over (dd.steps at the script's end: they raise
        LoopLeft); otherwise no collective call at all (the call's outcome decides, or ends
        the job)."""
        self.abandoned = "told" if tell else "alone"
        steps.close()

    def steps(self):
        """The run, step by step: yields a :class:`Step` after the initial state and after
        every step; closing the generator stops the run at that step (status "stopped")."""
        self.lock = RunLock(self.out, self.comm)
        try:
            with StopSignals() as self.signals:
                if self._set_up():
                    yield from self._loop()
        finally:
            self.lock.release()

    # -- set-up: resume point, folder claim, the model, summary and files
    def _set_up(self) -> bool:
        """False when a restart finds nothing to do (the summary is the previous one)."""
        ex, comm, o = self.ex, self.comm, self.options
        self.wall_start = time.perf_counter()
        c = self.configured  # the problem as this run has it (Problem.configure)
        params, grid, n, h, mesh_file = c.params, c.time, c.n, c.h, c.mesh_file
        self.grid = grid
        self.settings = {"example": ex.id, "n": n, "h": h, "k": grid.k,
                         "overrides": o["overrides"] or {},
                         "mesh_file": str(mesh_file) if mesh_file else None}
        if ex.own:  # an own problem: a restart must continue the same model and data
            self.settings.update(model=ex.model_id, parameters=params.as_dict())
        previous = previous_run(self.out, comm)
        resume = None
        if o["restart"]:
            resume = checkpoint.resume_point(self.out, self.settings, grid, previous, comm,
                                             parameters=params.as_dict())
            if resume is None:
                if comm.rank == 0:
                    print(f"damage-dolfinx: nothing to do: the run in {str(self.out)!r} ended "
                          f"({previous['status']}) at t = {previous['t_final']:.6g} after "
                          f"{previous['steps_done']} steps; its outputs are unchanged"
                          + (" (a larger T continues it)" if previous["status"] == "completed"
                             else ""), flush=True)
                self.summary = previous
                return False
        self.xdmf_name = f"fields_from_step{resume[1]['step']}.xdmf" if resume else "fields.xdmf"
        planned = {"summary.json", "history.csv", self.xdmf_name, self.xdmf_name[:-5] + ".h5",
                   self.xdmf_name + ".bak", "fields.xdmf", "fields.xdmf.tmp", "fields_final.npz",
                   "checkpoint.json",
                   *checkpoint.GENERATIONS, *(fig.filename for fig in ex.figures
                                               if o["figures"]),
                   *([HISTORY_FIGURE] if o["figures"] else [])}
        description = previous["description"] if previous else None
        claim = (self.out, "run", planned, o["restart"], o["overwrite"], comm, description)
        claim_folder(*claim, apply=False)
        self.path, self.resume = resume or (None, None)
        if self.resume:
            repaired = comm.bcast(io.repair_xdmf(self.out) if comm.rank == 0 else None)
            if repaired and comm.rank == 0:
                print(f"damage-dolfinx: {', '.join(repaired)} restored to its last complete "
                      "output time (the run was killed while writing it)", file=sys.stderr,
                      flush=True)
        self._build_model(mesh_file)
        self._check_drawable()
        self.settings["fingerprint"] = checkpoint.verify_fingerprint(self.ex, self.stepper,
                                                                     self.resume, self.out)
        claim_folder(*claim)
        self._check_checkpoints()
        self._open_summary(params, n)
        self._open_files()
        return True

    def _build_model(self, mesh_file):
        """The model, before any step: one that cannot set up its solvers is refused input (its
        declarations are checked where every model is built, problem/stages.py)."""
        o = self.options
        try:
            self.stepper = solver_step(
                lambda: self.ex.build(self.comm, o["n"], o["k"], o["T"], o["h"], o["overrides"],
                                      mesh_file, self.configured), "cannot set up the solvers")
        except ConvergenceError as exc:
            raise InputError(str(exc)) from None
        ContactOutput.for_model(self.stepper)  # contact quantities in history.csv and XDMF

    def _check_drawable(self):
        """The figures draw simplex meshes (triangles, tetrahedra): a run of a quadrilateral
        or hexahedral mesh with figures is refused here, before any step (not after it)."""
        if not (self.options["figures"] and self.ex.figures):
            return
        topology = self.stepper.mesh.topology
        cell = getattr(topology, "cell_type", None)
        if cell is None:  # DOLFINx with mixed topologies: cell_types
            cell = topology.cell_types[0]
        name = getattr(cell, "name", str(cell))
        if name not in ("triangle", "tetrahedron", "interval"):
            raise InputError(f"the figures draw triangle and tetrahedron meshes, this mesh has "
                             f"{name} cells: run it with figures=False (--no-figures), or on "
                             "a simplex mesh")

    def _check_checkpoints(self):
        stepper, o = self.stepper, self.options
        if (self.resume or o["checkpoint_every"]) and not stepper.checkpoint_supported:
            raise InputError(f"example {self.ex.id} does not support checkpoints")
        self.supported = stepper.checkpoint_supported
        try:
            if self.supported:
                stepper.checkpoint_state()
        except InputError:  # a variant without checkpoints (2.3 memory_mode=sum)
            if self.resume or o["checkpoint_every"]:
                raise
            self.supported = False
        self.N = stepper.num_steps
        self.write_every = o["write_every"] or max(1, self.N // 20)
        self.checkpoints = self.supported and bool(o["checkpoint_every"]
                                                   or o["checkpoint_seconds"])

    def _open_summary(self, params, n):
        ex, stepper, comm, grid, resume = self.ex, self.stepper, self.comm, self.grid, self.resume
        self.summary = {
            "schema": "damage-dolfinx/summary/v1", "example": ex.id, "title": ex.title,
            "section": ex.section, "status": "running", "parameters": params.as_dict(),
            "n": n, "h": stepper.data.geometry.h, "k": grid.k, "T": grid.T, "num_steps": self.N,
            "history_every": self.options["history_every"],
            "steps_done": 0, "t_final": 0.0, "mpi_size": comm.size,
            "mesh": stepper.mesh_info(), "assumptions": ex.assumptions,
            "reading": departures.record(ex),
            "outputs": {"xdmf": self.xdmf_name, "history": "history.csv",
                        "final_fields": "fields_final.npz", "figures": []},
            "environment": io.environment(comm)}
        self.previous_wall = resume["wall_time_s"] if resume else 0.0
        if resume:
            self.summary["restarts"] = resume.get("restarts", []) + [
                {"step": resume["step"], "mpi_size": comm.size,
                 "previous_mpi_size": resume["mpi_size"]}]
        self.last_checkpoint = {"time": time.perf_counter(),
                                "step": resume["step"] if resume else None}
        self.recorded = None  # the step whose scalars the summary holds
        self.fields_at = None  # the step whose fields the XDMF series holds last

    def _open_files(self):
        stepper, comm, out = self.stepper, self.comm, self.out
        self.model_columns = list(stepper.extra_history_columns)
        columns = ["step", "t", "u_L2", "eps_u_L2", "zeta_min", "zeta_max", "zeta_mean",
                   "damage_its", "mech_its", "snes_its", "step_time_s", *self.model_columns]
        files = {}

        def open_files():
            files["xdmf"] = io.XDMFSeries(out / self.xdmf_name, stepper.mesh, out / "fields.xdmf",
                                          self.resume["t"] if self.resume else None)
            files["history"] = io.CSVHistory(out / "history.csv", columns, comm,
                                             keep_until_step=self.resume["step"]
                                             if self.resume else None)
        io.collective(comm, out, f"{self.xdmf_name} / history.csv (opening)", open_files)
        self.columns = set(columns)
        self.xdmf, self.history = files["xdmf"], files["history"]
        self.summary["outputs"].update(io.series_outputs(self.xdmf))
        self.report = Progress(self.ex.id, self.N, comm, enabled=self.options["progress"])
        # models without track() compute their scalars (whatever they keep track of stays right)
        self.track = getattr(stepper, "track", None) or stepper.scalars

    # -- the loop
    def _loop(self):
        stepper, N = self.stepper, self.N
        stop = None
        try:
            stats, scalars = self._initial()
            self.report(stepper.n, stepper.t, stats, scalars, force=True)
            try:
                yield Step(self)
            except GeneratorExit:
                if self.abandoned == "alone" or not together(
                        self, 2 if self.abandoned else 1) or self.abandoned:
                    raise
                stop = "stopped"
                if stepper.n < N and self.supported:
                    self.save_checkpoint()
            else:
                together(self, 0)
            while stop is None and stepper.n < N:
                stop, step = self._step()
                if stop:
                    break
                try:  # here, not in _step: a close reaches a nested generator's caller too
                    yield Step(self)
                except GeneratorExit:  # the caller stopped here: the outputs of a stop
                    if self.abandoned == "alone" or not together(
                        self, 2 if self.abandoned else 1) or self.abandoned:
                        raise
                    self._outputs("stopped", *step)
                    stop = "stopped"
                else:
                    together(self, 0)
            self._finish(stop)
        except (ConvergenceError, io.OutputError) as exc:
            self._failed(exc)
            raise

    def _initial(self):
        stepper = self.stepper
        start = time.perf_counter()
        if self.resume:
            checkpoint.load(self.path, stepper.checkpoint_state())
            stepper.restore(self.resume["step"])
            self.check_state()
            stats = {}
            scalars = self.record(stats, 0.0, row=False)  # the summary from the state on disk
            self.write_fields()
        else:
            stats = solver_step(stepper.initialize, self.at("the initial solve"))
            self.check_state()
            scalars = self.record(stats, time.perf_counter() - start)
            self.write_fields()
            self.timed_figures()
        return stats, scalars

    def _step(self):
        """One step and its outputs; returns the reason to stop (or None) and what the outputs
        of a stop at this step need."""
        stepper, N, o = self.stepper, self.N, self.options
        start = time.perf_counter()
        stats = solver_step(stepper.advance, f"step {stepper.n + 1} (t = "
                                             f"{stepper.t + self.grid.k:.6g})")
        step_time = time.perf_counter() - start
        row = stepper.n % o["history_every"] == 0 or stepper.n == N
        if row:
            scalars = self.record(stats, step_time)
        else:  # between history rows: only the extremes over all steps
            self.track()
            scalars = stepper.scalars
        since_checkpoint, elapsed, signum = self.end_of_step()
        if signum and stepper.n < N:
            self.up_to_date(stats, step_time)
            self.interrupt(signum)
        stop = stepper.stop_reason()
        if o["time_limit"] and elapsed > o["time_limit"]:
            stop = stop or "time_limit"
        step = (stats, step_time, row)
        scalars, row = self._outputs(stop, step, scalars, since_checkpoint)
        self.timed_figures()
        self.report(stepper.n, stepper.t, stats, scalars, force=bool(stop))
        return stop, ((stats, step_time, row), scalars, None)

    def _outputs(self, stop, step, scalars, since_checkpoint):
        """The history row, fields and checkpoint a step is due (a stopping step has them
        all); ``since_checkpoint`` None: no timed checkpoint."""
        stepper, N = self.stepper, self.N
        stats, step_time, row = step
        if stop and not row:  # the stopping step always has its row
            scalars, row = self.record(stats, step_time), True
        if (stop or stepper.n % self.write_every == 0 or stepper.n == N) \
                and self.fields_at != stepper.n:
            self.up_to_date(stats, step_time)
            self.write_fields()
        if (stop and stepper.n < N) or (since_checkpoint is not None
                                        and self.checkpoint_due(since_checkpoint)):
            self.up_to_date(stats, step_time)
            self.save_checkpoint()
        return scalars, row

    def _finish(self, stop):
        stepper, comm, out = self.stepper, self.comm, self.out
        status = stop or "completed"  # recorded last: a kill before the end leaves "running"
        if self.checkpoints and self.last_checkpoint["step"] != stepper.n:
            self.save_checkpoint()  # so that --restart with a larger T continues from here
        self.history.close()
        stepper.update_output()
        final = {"u": stepper.u, "zeta": stepper.zeta, "von_mises": stepper.von_mises}
        final.update({f.name: f for f in stepper.output_fields if f.name not in final})
        io.collective(comm, out, self.at("fields_final.npz"), io.save_final_fields,
                      out / "fields_final.npz", final)
        if self.options["figures"]:
            stepper.update_output()
            for fig in self.ex.figures:
                if not fig.times:
                    self.figure(fig)
            self.history_figure()
        self.summary["timings_s"] = dict(getattr(stepper, "timings", {}))
        self.summary.update(status=status, wall_time_s=self.wall_time())
        self.write_summary()
        if comm.rank == 0 and self.options["progress"]:
            print(f"[{self.ex.id}] {self.summary['status']} at t = {stepper.t:.5g} after "
                  f"{stepper.n} steps in {self.summary['wall_time_s']:.1f} s on {comm.size} "
                  f"rank(s); output in {out}", flush=True)

    def _failed(self, exc):
        self.summary.update(status="failed", error=str(exc), wall_time_s=self.wall_time())
        if self.comm.rank == 0:
            self.lock.free_reserve()
            try:  # where space allows (the lock's reserve is freed for it)
                io.write_json(self.out / "summary.json", self.summary, self.comm)
            except OSError:
                pass
        self.history.close()
