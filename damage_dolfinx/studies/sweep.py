"""Parameter sweeps: one problem run over a grid of parameter values, each point a normal run
folder, the points shared out among the ranks, resumable, gathered into one table and a plot.

Layout of the sweep folder ``out``::

    points.json    the grid, and for every point its folder and parameter values
    point_<i>/     the run folder of point i (summary.json, history.csv, fields.xdmf, ...)
    sweep.csv      one row per point: its parameter values, status and final scalars
    sweep.png      a chosen scalar against the swept parameters
    summary.json   the sweep's own summary

The points are the Cartesian product of the grid's value lists, in the order of the grid's
keys (the last key varies fastest). Each rank runs its share of the points one after another
on its own (``MPI.COMM_SELF``), as :func:`damage_dolfinx.converge` shares out its coarse cells;
a problem whose mesh was built on all ranks (not a mesh family or a file) runs its points on
all ranks together instead. A point whose ``summary.json`` says "completed" is kept as it is
when the sweep runs again; a point that was interrupted reruns from its checkpoint with
``restart=True``, or from the start otherwise.
"""
from __future__ import annotations

import csv
import io as io_module
import itertools
import json
import math
import time
from pathlib import Path

from mpi4py import MPI

from damage_dolfinx.parameters import InputError

#: points.json schema
SCHEMA = "damage-dolfinx/sweep/v1"
#: summary columns of every point in sweep.csv, before the model's final scalars
STATUS_COLUMNS = ["status", "steps_done", "t_final", "wall_time_s"]


def parse_values(text: str, name: str) -> list:
    """``"0.01,0.1,1"`` -> [0.01, 0.1, 1.0] (numbers where they parse, text otherwise)."""
    values = []
    for item in text.split(","):
        item = item.strip()
        if not item:
            raise InputError(f"--set {name}=...: an empty value in {text!r}")
        try:
            values.append(float(item))
        except ValueError:
            values.append(item)
    return values


def check_grid(grid) -> dict:
    """The grid as {name: [values]}, or InputError: no parameter, an empty list, a
    non-finite number, a value given twice."""
    if not isinstance(grid, dict) or not grid:
        raise InputError("a sweep needs a grid {parameter: [values]} with at least one parameter")
    out = {}
    for name, values in grid.items():
        if not isinstance(name, str) or not name:
            raise InputError(f"sweep parameter names must be text, got {name!r}")
        if isinstance(values, (str, bytes)) or not hasattr(values, "__iter__"):
            values = [values]
        values = list(values)
        if not values:
            raise InputError(f"sweep parameter {name!r} has an empty list of values")
        for v in values:
            if isinstance(v, bool) or not isinstance(v, (int, float, str)):
                raise InputError(f"sweep parameter {name!r}: value {v!r} is not a number or text")
            if isinstance(v, (int, float)) and not math.isfinite(v):
                raise InputError(f"sweep parameter {name!r}: value {v} is not finite")
        if len(set(values)) != len(values):
            twice = sorted({str(v) for v in values if values.count(v) > 1})
            raise InputError(f"sweep parameter {name!r}: value(s) {', '.join(twice)} given twice")
        out[name] = values
    return out


def grid_points(grid: dict) -> list:
    """[{name: value}] of every point, the last parameter varying fastest."""
    names = list(grid)
    return [dict(zip(names, combo)) for combo in itertools.product(*grid.values())]


def _runs_on_all_ranks(case) -> bool:
    """A Problem whose mesh is already built (distributed over its own ranks)."""
    mesh = getattr(case, "mesh", None)
    if mesh is None or isinstance(mesh, (str, Path)):
        return False
    return not (callable(mesh) and not isinstance(mesh, tuple))


def _state(folder: Path) -> str:
    """'completed', 'checkpoint' (interrupted, resumable), 'started' or 'new'."""
    try:
        status = json.loads((folder / "summary.json").read_text()).get("status")
    except (OSError, ValueError):
        status = None
    if status == "completed":
        return "completed"
    if (folder / "checkpoint.json").is_file():
        return "checkpoint"
    return "started" if folder.exists() else "new"


def _describe(values: dict) -> str:
    return ", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}"
                     for k, v in values.items())


def sweep(problem, out, grid, *, n=None, k=None, T=None, restart=False, max_points=None,
          plot="zeta_min", figures=True, progress=True, comm=MPI.COMM_WORLD) -> dict:
    """Run ``problem`` (a :class:`~damage_dolfinx.Problem` or a catalogue id) at every point of
    ``grid`` = ``{parameter: [values]}`` into ``out/point_<i>``; returns the sweep summary.

    Bad grids (no parameter, an empty list, a non-finite value, a value given twice, an
    unknown parameter or a value the model refuses) raise :class:`~damage_dolfinx.InputError`
    before any run. Finished points are kept when the sweep runs again; interrupted ones
    rerun, from their checkpoint with ``restart=True``. ``max_points``: run at most this many
    of the points not yet finished, then stop (the others stay pending). ``plot``: the final
    scalar drawn against the swept parameters in ``sweep.png``. ``n``, ``k``, ``T`` apply to
    every point."""
    from damage_dolfinx.runtime.collective import outcome
    from damage_dolfinx.validation import check_sweep
    with outcome(comm):
        checked = check_sweep(grid, n, k, T, restart, max_points, plot, figures, progress)
        return _sweep(problem, out, grid, comm=comm, **checked)


def _sweep(problem, out, grid, *, n, k, T, restart, max_points, plot, figures, progress,
           comm) -> dict:
    from damage_dolfinx.runtime import io
    from damage_dolfinx.runtime.collective import describe, mark, track
    from damage_dolfinx.runtime.runner import resolve
    from damage_dolfinx.runtime.runner import run as run_one
    from damage_dolfinx.runtime.signals import RunInterrupted

    wall_start = time.perf_counter()
    grid = check_grid(grid)
    points = grid_points(grid)
    ex = resolve(problem)
    checked_at = time.perf_counter()
    for i, values in enumerate(points):  # every point is checked before any work
        ex.configure(n, k, T, None, dict(values))
        if progress and comm.rank == 0 and time.perf_counter() - checked_at > 2.0:
            checked_at = time.perf_counter()
            print(f"[sweep {ex.id}] checking the grid: {i + 1}/{len(points)} points",
                  flush=True)
    out = Path(out)
    mapping = {"schema": SCHEMA, "case": ex.id, "grid": grid, "n": n, "k": k, "T": T,
               "points": [{"index": i, "folder": f"point_{i}", "values": values}
                          for i, values in enumerate(points)]}
    existing = None
    if comm.rank == 0 and (out / "points.json").is_file():
        try:
            existing = json.loads((out / "points.json").read_text())
        except ValueError:
            existing = {}
    existing = comm.bcast(existing, root=0)
    if existing is not None and {key: existing.get(key) for key in mapping} != \
            json.loads(json.dumps(mapping)):
        raise InputError(f"{str(out)!r} holds another sweep (a different problem, grid, n, k or "
                         "T in its points.json); choose another out folder")
    out = io.prepare_output_dir(out, comm)
    states = claim_sweep_folder(out, len(points), restart, comm)
    track(out, "sweep")
    if comm.rank == 0:
        io.write_json(out / "points.json", mapping, comm)
        io.write_json(out / "summary.json", {"schema": SCHEMA, "case": ex.id, "status": "running",
                                              "points": len(points)}, comm)

    pending = [i for i, s in enumerate(states) if s != "completed"]
    todo = pending[:max_points] if max_points else pending
    together = _runs_on_all_ranks(problem) and comm.size > 1
    mine = todo if together else todo[comm.rank::comm.size]
    run_comm = comm if together else MPI.COMM_SELF
    if comm.rank == 0 and progress:
        print(f"[sweep {ex.id}] {len(points)} points, {len(points) - len(pending)} finished, "
              f"running {len(todo)} on {comm.size} rank(s)", flush=True)
    failures = {}
    for i in mine:
        values = points[i]
        folder = out / f"point_{i}"
        resume = restart and states[i] == "checkpoint"
        start = time.perf_counter()
        try:
            summary = run_one(problem, folder, n=n, k=k, T=T, overrides=dict(values),
                              progress=False, figures=figures, restart=resume,
                              overwrite=not resume, comm=run_comm)
            status = summary["status"]
        except (RunInterrupted, KeyboardInterrupt):
            raise  # the sweep stops (collective.outcome decides for every rank)
        except Exception as exc:  # noqa: BLE001 - a point fails, the sweep goes on
            if together:
                raise
            if run_comm.rank == 0:
                mark(folder, exc)
            status = f"failed ({describe(exc)})"
            failures[i] = describe(exc)
        if progress and run_comm.rank == 0:
            print(f"[sweep {ex.id}] point {i} ({_describe(values)}): {status} in "
                  f"{time.perf_counter() - start:.1f} s (rank {comm.rank})", flush=True)
    failures = {i: why for part in comm.allgather(failures) for i, why in part.items()}

    summary = None
    if comm.rank == 0:
        rows, scalars = [], []
        for i, values in enumerate(points):
            row = {"point": i, "folder": f"point_{i}", **values}
            try:
                s = json.loads((out / f"point_{i}" / "summary.json").read_text())
            except (OSError, ValueError):
                s = {"status": "pending"}
            row.update({c: s.get(c, "") for c in STATUS_COLUMNS})
            for key, value in (s.get("final") or {}).items():
                if isinstance(value, (int, float)) and not isinstance(value, bool):
                    row[key] = value
                    if key not in scalars:
                        scalars.append(key)
            rows.append(row)
        columns = ["point", "folder", *grid, *STATUS_COLUMNS, *scalars]
        def table(f):
            text = io_module.StringIO()
            writer = csv.DictWriter(text, fieldnames=columns, restval="")
            writer.writeheader()
            writer.writerows(rows)
            f.write(text.getvalue().encode())
        io.collective(MPI.COMM_SELF, out, "sweep.csv", io.atomic_write_bytes, out / "sweep.csv",
                      table)
        done = [r for r in rows if r["status"] == "completed"]
        if plot and plot not in scalars and done:  # the runs are kept: a warning, no plot
            import sys
            print(f"damage-dolfinx: warning: no plot: {plot!r} is not a final scalar of this "
                  f"problem (known: {', '.join(scalars)})", file=sys.stderr, flush=True)
            plot = None
        if plot and done:
            io.collective(MPI.COMM_SELF, out, "sweep.png", plot_sweep, out / "sweep.png", done,
                          grid, plot, ex.id)
        failed = sorted(i for i, r in enumerate(rows) if str(r["status"]).startswith("failed")
                        or i in failures)
        status = "failed" if failed else ("completed" if len(done) == len(points) else
                                          "incomplete")
        summary = {"schema": SCHEMA, "case": ex.id, "status": status, "grid": grid,
                   "points": len(points), "completed": len(done), "failed": failed,
                   "errors": {str(i): why for i, why in sorted(failures.items())},
                   **({"error": f"{len(failed)} of {len(points)} points failed"} if failed
                      else {}),
                   "pending": [r["point"] for r in rows if r["status"] != "completed"],
                   "ran": todo, "mpi_size": comm.size, "points_on_all_ranks": together,
                   "csv": "sweep.csv", "plot": "sweep.png" if plot and done else None,
                   "wall_time_s": time.perf_counter() - wall_start}
        io.write_json(out / "summary.json", summary, comm)
        if progress:
            print(f"[sweep {ex.id}] {len(done)}/{len(points)} points completed"
                  + (f", {len(failed)} failed" if failed else "") + " in "
                  f"{summary['wall_time_s']:.1f} s; table {out / 'sweep.csv'}", flush=True)
    return comm.bcast(summary, root=0)


def claim_sweep_folder(out, count, restart, comm) -> list:
    """The folder rules for a sweep (rank 0 decides, every rank gets the answer): a folder
    holding a run or a convergence study is refused, and so are files the package did not
    write (in the folder or in a point's folder); the manifest then lists the sweep's files
    and point folders. Returns the state of every point (``_state``)."""
    from damage_dolfinx.runtime import runfolder
    result = None
    if comm.rank == 0:
        try:
            result = _claim_sweep(Path(out), count)
        except InputError as exc:
            result = exc
        except OSError as exc:
            result = InputError(f"cannot use {str(out)!r}: {exc.strerror or exc}")
    result = comm.bcast(result, root=0)
    if isinstance(result, InputError):
        raise result
    del runfolder
    return result


def _claim_sweep(out: Path, count: int) -> list:
    from damage_dolfinx.runtime import runfolder
    names = {f"point_{i}" for i in range(count)} | set(SWEEP_FILES)
    present = {p.name for p in out.iterdir()}
    known = runfolder.read_manifest(out)
    if known is not None and known[0] != "sweep":
        what = {"run": "a run", "study": "a convergence study"}[known[0]]
        raise InputError(f"{str(out)!r} holds {what}; a sweep needs a folder of its own: "
                         "choose another --out (nothing was touched)")
    if known is None:
        legacy = runfolder.folder_contents(out)[0]
        if legacy is not None:
            what = {"run": "a run", "study": "a convergence study"}[legacy]
            raise InputError(f"{str(out)!r} holds {what}; a sweep needs a folder of its own: "
                             "choose another --out (nothing was touched)")
        ours = set() if "points.json" not in present else \
            {n for n in present if n in names}  # a sweep written before manifests
    else:
        ours = known[1]
    others = present - ours - {runfolder.MANIFEST, *runfolder.HIDDEN} - \
        {n + ".tmp" for n in ours}
    if others:
        raise InputError(f"{str(out)!r} holds {runfolder._listing(others)}, not written by "
                         f"damage-dolfinx (not in its {runfolder.MANIFEST}): move them or "
                         "choose another --out (nothing was touched)")
    states = []
    for i in range(count):
        folder = out / f"point_{i}"
        state = _state(folder)
        if folder.is_symlink() or (folder.exists() and not folder.is_dir()):
            raise InputError(f"{str(folder)!r} is not a folder of this sweep: move it or choose "
                             "another --out (nothing was touched)")
        if folder.is_dir():
            kind, _, strangers = runfolder.folder_contents(folder)
            if strangers:
                raise InputError(f"{str(folder)!r} holds {runfolder._listing(strangers)}, not "
                                 "written by damage-dolfinx: move them or choose another --out "
                                 "(nothing was touched)")
            if kind not in (None, "run"):
                raise InputError(f"{str(folder)!r} holds a convergence study: choose another "
                                 "--out (nothing was touched)")
        states.append(state)
    runfolder.write_manifest(out, "sweep", names | (ours & present))
    return states


#: files of a sweep folder (besides point_<i>/ and the manifest)
SWEEP_FILES = ("points.json", "sweep.csv", "sweep.png", "summary.json")


def plot_sweep(path, rows, grid, scalar, label):
    """``scalar`` against the first swept parameter with several values, one line per
    combination of the others."""
    from damage_dolfinx.viz import figstyle
    names = list(grid)
    x_name = next((name for name in names if len(grid[name]) > 1), names[0])
    others = [name for name in names if name != x_name]
    fig, ax = figstyle.plt().subplots(figsize=(6.4, 4.2))
    numeric = all(isinstance(v, (int, float)) for v in grid[x_name])
    for combo in itertools.product(*(grid[name] for name in others)):
        sel = [r for r in rows if all(r[name] == v for name, v in zip(others, combo))]
        if not sel:
            continue
        order = grid[x_name]
        sel.sort(key=lambda r: order.index(r[x_name]))
        xs = [r[x_name] if numeric else str(r[x_name]) for r in sel]
        ax.plot(xs, [r[scalar] for r in sel], "o-", ms=5,
                label=_describe(dict(zip(others, combo))) or None)
    if numeric and min(grid[x_name]) > 0 and max(grid[x_name]) >= 10 * min(grid[x_name]):
        ax.set_xscale("log")
    ax.set_xlabel(x_name)
    ax.set_ylabel(scalar)
    ax.grid(True, alpha=0.3)
    if others:
        ax.legend(fontsize=8)
    figstyle.save(fig, path, title=f"{label}: {scalar} over the sweep")
