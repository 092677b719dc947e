"""What a run writes as it goes (:class:`RunRecords`, the bookkeeping half of
:class:`~damage_dolfinx.runtime.loop.Run`): summary.json, history rows with the column contract,
XDMF fields, checkpoints, figures, the per-step collective checks and the interrupt."""
from __future__ import annotations

import signal
import sys
import time

import numpy as np
from mpi4py import MPI

from damage_dolfinx.numerics.damage import fast_path_counts
from damage_dolfinx.numerics.solvers import ConvergenceError
from damage_dolfinx.runtime import checkpoint, io
from damage_dolfinx.runtime.figures import draw_figure
from damage_dolfinx.runtime.guards import state_problem
from damage_dolfinx.runtime.runfolder import add_to_manifest
from damage_dolfinx.runtime.signals import RunInterrupted

def _is_number(value) -> bool:
    import numbers
    import numpy as np
    return isinstance(value, (numbers.Real, np.floating, np.integer)) and \
        not isinstance(value, (bool, np.bool_))


#: the figure of history.csv that every run draws with its other figures
HISTORY_FIGURE = "history.png"


class ColumnError(RuntimeError):
    """A model reported a scalar that no history column takes, or left a declared one out."""


class RunRecords:
    # -- what a step writes
    def wall_time(self) -> float:
        return self.previous_wall + time.perf_counter() - self.wall_start

    def at(self, name):
        return f"{name} at step {self.stepper.n} (t = {self.stepper.t:.6g})"

    def write_summary(self):
        io.collective(self.comm, self.out, self.at("summary.json"), io.write_json,
                      self.out / "summary.json", self.summary, self.comm)

    def save_checkpoint(self):
        self.write_summary()  # first: the summary is never behind the checkpoint
        stepper = self.stepper
        checkpoint.save(self.out, stepper.checkpoint_state(), {
            **self.settings, "parameters": self.summary["parameters"], "step": stepper.n,
            "t": stepper.t, "mpi_size": self.comm.size, "wall_time_s": self.wall_time(),
            "restarts": self.summary.get("restarts", [])}, self.comm)
        self.last_checkpoint.update(time=time.perf_counter(), step=stepper.n)

    def end_of_step(self):
        """One allreduce per step: seconds since the last checkpoint and since the start, the
        signal received (if any) and whether the history row failed, agreed by all ranks."""
        now = time.perf_counter()
        bad, detail = state_problem(self.stepper)
        state = np.array([now - self.last_checkpoint["time"], now - self.wall_start,
                          self.signals.signum, float(self.history.error is not None), bad])
        self.comm.Allreduce(MPI.IN_PLACE, state, op=MPI.MAX)
        if state[3]:
            reason = self.comm.bcast(io.describe(self.history.error, self.out)
                                     if self.comm.rank == 0 else None)
            raise io.OutputError(f"cannot write {self.at('history.csv')}: {reason}")
        if state[4]:
            self.check_state()  # raises (the detail from a rank that has it)
        return state[0], state[1], int(state[2])

    def check_state(self):
        """Stop on a NaN/Inf or a zeta outside [zeta_star, 1] on any rank (collective)."""
        bad, detail = state_problem(self.stepper)
        ranks = self.comm.allgather(detail if bad else None)
        detail = next((d for d in ranks if d), None)
        if detail:
            raise ConvergenceError(f"{self.at('the state')}: {detail}; the run is stopped (the "
                                   "model or its data gave numbers that cannot be right)")

    def checkpoint_due(self, since_checkpoint) -> bool:
        if not self.supported:
            return False
        if self.options["checkpoint_every"]:
            return self.stepper.n % self.options["checkpoint_every"] == 0
        seconds = self.options["checkpoint_seconds"]
        return bool(seconds) and since_checkpoint > seconds

    def record(self, stats, step_time, row=True):
        """The step's scalars into the summary and (``row``) a history.csv row."""
        stepper = self.stepper
        scalars = stepper.scalars()
        if row:
            values = {"step": stepper.n, "t": stepper.t, **scalars, **stats,
                      "step_time_s": f"{step_time:.4g}"}
            self.check_columns(values)
            self.history.write(values)
        self.recorded = stepper.n
        self.summary.update(steps_done=stepper.n, t_final=stepper.t, final=scalars,
                            iterations={**stepper.iteration_totals(),
                                        **fast_path_counts(stepper)},
                            wall_time_s=self.wall_time(), **stepper.summary_extra())
        return scalars

    def check_columns(self, values):
        """Every value has its column, and every column the model declares has its value
        after each step (the initial state has no step statistics)."""
        wrong = [f"{key} = {value!r}" for key, value in values.items()
                 if key != "step_time_s" and value is not None and not _is_number(value)]
        if wrong:
            raise ColumnError(f"model {type(self.stepper).__name__}: history values must be "
                              f"numbers, got {', '.join(wrong[:3])} (a scheme's solve returns "
                              "its iteration count, a scalar its value)")
        extra = sorted(set(values) - self.columns)
        missing = sorted(set(self.model_columns) - set(values)) if values["step"] > 0 else []
        if extra or missing:
            raise ColumnError(
                f"model {type(self.stepper).__name__}: "
                + (f"scalars {extra} have no history column (declare them in "
                   "history_columns)" if extra else "")
                + ("; " if extra and missing else "")
                + (f"declared columns {missing} were not written" if missing else ""))

    def up_to_date(self, stats, step_time):
        """The summary of the current step (a step between history rows has none yet)."""
        if self.recorded != self.stepper.n:
            self.record(stats, step_time, row=False)

    def write_fields(self):
        self.fields_at = self.stepper.n
        self.stepper.update_output()
        io.collective(self.comm, self.out, self.at(f"{self.xdmf_name} (+ .h5)"),
                      self.xdmf.write, self.stepper.output_fields, self.stepper.t)
        self.write_summary()

    def figure(self, fig, suffix=""):
        """Draw one figure. A figure whose drawing fails (an error of the drawing, not of the
        disk) is a figure failure, not the computation's: it is listed in the summary
        (``outputs.figure_failures``) and on stderr, and the run goes on with its status. A
        file that cannot be written (full disk, I/O error) stays an output error of the run
        (io.collective). Every rank agrees on both."""
        filename = fig.filename.replace(".png", f"{suffix}.png")
        failure = []

        def draw():
            add_to_manifest(self.out, [filename], self.comm)
            try:
                entry = draw_figure(self.ex, fig, self.stepper, self.out, suffix)
            except OSError:
                raise
            except Exception as exc:  # noqa: BLE001 - any drawing error: the figure's
                failure.append(f"{type(exc).__name__}: {exc}")
                return
            self.summary["outputs"]["figures"].append(entry)
        io.collective(self.comm, self.out, self.at(filename), draw)
        failures = [f for f in self.comm.allgather(failure[0] if failure else None) if f]
        if failures:
            if not failure:  # another rank failed to draw: this rank's entry is not kept
                entries = self.summary["outputs"]["figures"]
                if entries and entries[-1].get("file") == filename:
                    entries.pop()
            self.summary["outputs"].setdefault("figure_failures", []).append(
                {"file": filename, "error": failures[0]})
            if self.comm.rank == 0:
                print(f"damage-dolfinx: figure {filename} not drawn at step {self.stepper.n} "
                      f"(the computation is not affected): {failures[0]}", file=sys.stderr,
                      flush=True)

    def history_figure(self):
        """history.png: every history.csv column over time (rank 0 draws; collective)."""
        def draw():
            add_to_manifest(self.out, [HISTORY_FIGURE], self.comm)
            if self.comm.rank == 0:
                from damage_dolfinx.viz.history_figure import plot_run_history
                plot_run_history(self.out / "history.csv", self.out / HISTORY_FIGURE,
                                 title=f"{self.ex.id}: history of the run ({self.comm.size} "
                                       f"rank{'s' if self.comm.size > 1 else ''})")
            self.summary["outputs"]["figures"].append({"file": HISTORY_FIGURE})
        io.collective(self.comm, self.out, self.at(HISTORY_FIGURE), draw)

    def timed_figures(self):
        """Figures requested at the current time (Figure.times)."""
        for fig in self.ex.figures if self.options["figures"] else []:
            if any(abs(self.stepper.t - t) < 0.5 * self.grid.k for t in fig.times):
                self.stepper.update_output()
                self.figure(fig, suffix=f"_t{self.stepper.t:g}")

    def interrupt(self, signum):
        name = signal.Signals(signum).name
        if self.supported:
            self.save_checkpoint()
        self.summary.update(status="interrupted", signal=name, wall_time_s=self.wall_time())
        self.write_summary()
        kept = ("checkpoint written; restart=True continues the run" if self.supported
                else f"example {self.ex.id} has no checkpoints: the history and fields so far "
                "stay")
        raise RunInterrupted(signum, f"stopped by {name} after step {self.stepper.n} "
                                     f"(t = {self.stepper.t:.6g}): {kept}")
