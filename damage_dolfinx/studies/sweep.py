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
    from damage_dolfinx.runtime import io
    from damage_dolfinx.runtime.runner import resolve
    from damage_dolfinx.runtime.runner import run as run_one
    from damage_dolfinx.numerics.solvers import ConvergenceError

    wall_start = time.perf_counter()
    grid = check_grid(grid)
    if max_points is not None and (isinstance(max_points, bool) or int(max_points) != max_points
                                   or max_points < 1):
        raise InputError(f"max_points must be a whole number >= 1, got {max_points!r}")
    points = grid_points(grid)
    ex = resolve(problem)
    for values in points:  # every point is checked before any work (unknown names, values)
        ex.configure(n, k, T, None, dict(values))
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
    if comm.rank == 0:
        io.write_json(out / "points.json", mapping, comm)

    states = comm.bcast([_state(out / f"point_{i}") for i in range(len(points))]
                        if comm.rank == 0 else None, root=0)
    pending = [i for i, s in enumerate(states) if s != "completed"]
    todo = pending[:max_points] if max_points else pending
    together = _runs_on_all_ranks(problem) and comm.size > 1
    mine = todo if together else todo[comm.rank::comm.size]
    run_comm = comm if together else MPI.COMM_SELF
    if comm.rank == 0 and progress:
        print(f"[sweep {ex.id}] {len(points)} points, {len(points) - len(pending)} finished, "
              f"running {len(todo)} on {comm.size} rank(s)", flush=True)
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
        except ConvergenceError as exc:
            status = f"failed ({exc})"
        if progress and run_comm.rank == 0:
            print(f"[sweep {ex.id}] point {i} ({_describe(values)}): {status} in "
                  f"{time.perf_counter() - start:.1f} s (rank {comm.rank})", flush=True)
    comm.Barrier()

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
        with open(out / "sweep.csv", "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=columns, restval="")
            writer.writeheader()
            writer.writerows(rows)
        done = [r for r in rows if r["status"] == "completed"]
        if plot and plot not in scalars and done:  # the runs are kept: a warning, no plot
            import sys
            print(f"damage-dolfinx: warning: no plot: {plot!r} is not a final scalar of this "
                  f"problem (known: {', '.join(scalars)})", file=sys.stderr, flush=True)
            plot = None
        if plot and done:
            plot_sweep(out / "sweep.png", done, grid, plot, ex.id)
        summary = {"schema": SCHEMA, "case": ex.id, "grid": grid, "points": len(points),
                   "completed": len(done),
                   "pending": [r["point"] for r in rows if r["status"] != "completed"],
                   "ran": todo, "mpi_size": comm.size, "points_on_all_ranks": together,
                   "csv": "sweep.csv", "plot": "sweep.png" if plot and done else None,
                   "wall_time_s": time.perf_counter() - wall_start}
        io.write_json(out / "summary.json", summary, comm)
        if progress:
            print(f"[sweep {ex.id}] {len(done)}/{len(points)} points completed in "
                  f"{summary['wall_time_s']:.1f} s; table {out / 'sweep.csv'}", flush=True)
    return comm.bcast(summary, root=0)


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
