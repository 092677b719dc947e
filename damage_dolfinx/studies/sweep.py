"""Parameter sweeps: one problem run over a grid of parameter values, each point a normal run
folder, the points shared out among groups of ranks or among separate jobs, resumable,
gathered into one table and a plot.

Layout of the sweep folder ``out`` (sweep_folder.py: how several processes share it)::

    points.json    the grid, and for every point its index, folder and parameter values
    point_<i>/     the run folder of point i (summary.json, history.csv, fields.xdmf, ...)
    sweep.csv      one row per point, in the order of the points: its parameter values,
                   status and final scalars
    sweep.png      a chosen scalar against the swept parameters
    summary.json   the sweep's own summary

The points are the Cartesian product of the grid's value lists, in the order of the grid's
keys (the last key varies fastest); point ``i`` (0-based) is row ``i`` of ``sweep.csv``.

Who runs which point:

* ``ranks_per_point = R`` (default 1) splits the ranks into groups of R consecutive ranks
  (``comm.Split``); group g runs the points g, g + G, g + 2G, ... of those still to run (G
  groups, round robin), each point in parallel on its R ranks. R must divide the number of
  ranks. R = 1 is every rank running its share alone (``MPI.COMM_SELF``), as
  :func:`damage_dolfinx.converge` shares out its coarse cells. A problem whose mesh was built
  on all ranks (not a mesh family or a file) runs its points on all ranks together (R = the
  number of ranks).
* ``point = i`` runs point i alone, on all ranks of the call: a job of a scheduler's job
  array, each job one point, all writing the same folder (the first creates it, the others
  check that their grid and problem are the same; a completed point is not run again).

A point whose ``summary.json`` says "completed" is kept as it is when the sweep runs again; a
point that was interrupted reruns from its checkpoint with ``restart=True``, or from the
start otherwise; a point live in another process is left to it.

Every point is checked before any point runs, as ``run`` checks a run (its values, n, k, T
and its mesh, built once per mesh size); a refusal names the point. The sweep's status in
``summary.json`` is rebuilt from the points' records as each call ends, also a job of one point
that ends early (``sweep_folder.settle``): "running" while a point is live in another process,
else "failed", "completed" or "incomplete".

Failures: a point that fails on every rank of its group (a solver, a refused value, an
exception of user code raised alike) is recorded as failed and the sweep goes on (the
sweep's status "failed", exit status 3 on the command line); an exception on some ranks of a
group only ends the whole sweep within seconds (runtime/collective.py), with one line and the
statuses written. A stop signal that reaches some ranks only is passed on to every rank
(sweep_ranks.py): every point in progress stops at the end of its step with a checkpoint, and
every rank ends normally with exit status 128 + signal.
"""
from __future__ import annotations

import itertools
import json
import math
import time
from pathlib import Path

from mpi4py import MPI

from damage_dolfinx.core.parameters import InputError
from damage_dolfinx.studies.sweep_folder import (SCHEMA, STATUS_COLUMNS,  # noqa: F401
                                                 SWEEP_FILES, plot_sweep)
from damage_dolfinx.studies.sweep_folder import describe_values as _describe
from damage_dolfinx.studies.sweep_ranks import StopNotice, Relay, point_outcome


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


def sweep(problem, out, grid, *, n=None, k=None, T=None, restart=False, max_points=None,
          plot="zeta_min", figures=True, progress=True, ranks_per_point=None, point=None,
          comm=MPI.COMM_WORLD) -> dict:
    """Run ``problem`` (a :class:`~damage_dolfinx.Problem` or a catalogue id) at every point of
    ``grid`` = ``{parameter: [values]}`` into ``out/point_<i>``; returns the sweep summary.

    Bad grids (no parameter, an empty list, a non-finite value, a value given twice, an
    unknown parameter or a value the model refuses) raise :class:`~damage_dolfinx.InputError`
    before any run. Finished points are kept when the sweep runs again; interrupted ones
    rerun, from their checkpoint with ``restart=True``. ``max_points``: run at most this many
    of the points not yet finished, then stop (the others stay pending). ``plot``: the final
    scalar drawn against the swept parameters in ``sweep.png`` (a name that is not one of the
    final scalars a run of the problem reports is refused before any run, for the package's
    models; with a model of your own, after the runs: a warning, no plot). ``n``, ``k``, ``T``
    apply to every point. ``ranks_per_point``: the size of the groups of ranks that each run
    one point in parallel (a divisor of the number of ranks; default 1). ``point``: run only
    this point (0-based, the row of ``sweep.csv``), on all ranks, for a job of a job array;
    several processes may run points of the same ``out`` at once."""
    from damage_dolfinx.runtime.collective import outcome
    from damage_dolfinx.core.validation import check_sweep, communicator
    with outcome(communicator("comm", comm)):
        checked = check_sweep(grid, n, k, T, restart, max_points, plot, figures, progress,
                              out, comm)
        layout = _check_layout(ranks_per_point, point, checked["max_points"], comm)
        return _sweep(problem, out, grid, comm=comm, **checked, **layout)


def _check_layout(ranks_per_point, point, max_points, comm) -> dict:
    """ranks_per_point and point, refused (InputError) before any work when they cannot be."""
    from damage_dolfinx.core.validation import whole
    size = comm.size
    ranks = whole("ranks_per_point", ranks_per_point, allow_none=True)
    point = whole("point", point, low=0, allow_none=True)
    if ranks is not None and size % ranks:
        divisors = [d for d in range(1, size + 1) if size % d == 0]
        raise InputError(f"{ranks} ranks per point do not divide the {size} rank(s) of the sweep "
                         f"(possible: {', '.join(map(str, divisors))})")
    if point is not None and ranks not in (None, size):
        raise InputError(f"a single point runs on all {size} rank(s) of the call, not on "
                         f"{ranks} ranks per point")
    if point is not None and max_points is not None:
        raise InputError("a single point and a maximum number of points exclude each other")
    return {"ranks_per_point": ranks, "point": point}


def _check_point(ex, i, values, n, k, T, meshes, together, comm, plot=None):
    """Point ``i`` checked as ``run`` checks it before any work: its description
    (``configure``) and its mesh, built once per mesh size on ``comm`` (a size the geometry
    refuses, such as an n the hole does not fit, is refused here, before any point runs), and
    (``plot``) that ``plot`` is one of the final scalars its run reports
    (validation_scalars.py). InputError naming the point otherwise; returns the point's mesh
    size (n, h)."""
    c = None
    try:
        c = ex.configure(n, k, T, None, dict(values))
        size = (c.n, c.h)
        geometry = None
        if plot is not None or (not together and size not in meshes):
            geometry = c.make_geometry(comm, *size)
    except InputError as exc:
        raise _point_error(ex, i, values, n, k, T, exc, c is not None, comm) from None
    if plot is not None:  # the first point checked: the scalars its run reports
        from damage_dolfinx.problem.scalars import check_plot
        check_plot(plot, c, geometry, comm)
    return size


def _point_error(ex, i, values, n, k, T, exc, in_mesh, comm) -> InputError:
    """The refusal of point ``i``, named by the point only when its grid values cause it: the
    same settings without them (the sweep's n, k, T and the example's data) refused alike mean
    a setting of the whole sweep is wrong (a T below k, too many steps, an n the hole does not
    fit), which is said without a point. ``in_mesh``: the point's mesh refused it (built again
    without the grid values; every rank is here alike, as in the point's own check)."""
    try:
        c = ex.configure(n, k, T, None, {})
        if in_mesh:
            c.make_geometry(comm, c.n, c.h)
    except InputError as base:
        if str(base) == str(exc):
            return InputError(str(exc))
    return InputError(f"point {i} ({_describe(values)}): {exc}")


def _another_sweep(out, mapping, comm):
    """InputError when ``out``/points.json holds a sweep of another problem, grid, n, k or T
    (the refusal that names the folder's sweep, before a changed fingerprint is named)."""
    keys = ("schema", "case", "grid", "n", "k", "T")
    other = False
    if comm.rank == 0:
        try:
            saved = json.loads((Path(out) / "points.json").read_text())
            wanted = json.loads(json.dumps({key: mapping[key] for key in keys}))
            other = isinstance(saved, dict) and {key: saved.get(key) for key in keys} != wanted
        except (OSError, ValueError):
            other = False
    if comm.bcast(other, root=0):
        raise InputError(f"{str(out)!r} holds another sweep (a different problem, grid, n, k or "
                         "T in its points.json); choose another out folder")


def _shared(ex, grid) -> dict:
    """What every point shares besides n, k, T (points.json "shared"): the model, the reading
    and the parameters not swept (those a file can hold: numbers, text, flags)."""
    params = {}
    for name, value in ex.params.as_dict().items():
        if name not in grid and (value is None or isinstance(value, (bool, int, float, str))):
            params[name] = value if not (isinstance(value, float) and not math.isfinite(value)) \
                else str(value)
    return {"model": ex.model_id, "reading": ex.reading, "parameters": params}


def _sweep(problem, out, grid, *, n, k, T, restart, max_points, plot, figures, progress,
           ranks_per_point, point, comm) -> dict:
    from damage_dolfinx.runtime import io
    from damage_dolfinx.runtime.collective import track
    from damage_dolfinx.runtime.runner import resolve
    from damage_dolfinx.runtime.fingerprint import sweep_fingerprint
    from damage_dolfinx.studies.sweep_folder import open_sweep, settle

    wall_start = time.perf_counter()
    grid = check_grid(grid)
    points = grid_points(grid)
    if point is not None and point >= len(points):
        raise InputError(f"point {point} is not in the grid: its {len(points)} points are "
                         f"0 to {len(points) - 1}")
    together = _runs_on_all_ranks(problem)
    size = comm.size
    if together and ranks_per_point not in (None, size):
        raise InputError(f"the problem's mesh is built on all {size} rank(s): every point runs "
                         f"on all of them, not on {ranks_per_point} ranks per point")
    ranks = ranks_per_point or (size if together or point is not None else 1)
    ex = resolve(problem)
    checked_at = time.perf_counter()
    meshes = set()
    for i in (range(len(points)) if point is None else [point]):  # checked before any work
        meshes.add(_check_point(ex, i, points[i], n, k, T, meshes, together, comm,
                                plot if not meshes else None))
        if progress and comm.rank == 0 and time.perf_counter() - checked_at > 2.0:
            checked_at = time.perf_counter()
            print(f"[sweep {ex.id}] checking the grid: {i + 1}/{len(points)} points",
                  flush=True)
    mapping = {"schema": SCHEMA, "case": ex.id, "grid": grid, "n": n, "k": k, "T": T,
               "points": [{"index": i, "folder": f"point_{i}", "values": values}
                          for i, values in enumerate(points)],
               "shared": _shared(ex, grid)}
    try:
        mapping["fingerprint"] = sweep_fingerprint(ex, out, n, k, T, points[0], comm)
    except InputError:
        _another_sweep(out, mapping, comm)  # another grid, problem, n, k or T: said first
        raise
    out = io.prepare_output_dir(out, comm)
    states = open_sweep(out, mapping, point, comm)
    if point is None:  # a job of one point leaves the sweep's status to the record (others run)
        track(out, "sweep")
    try:
        return _run_points(problem, out, ex, points, states, mapping, n=n, k=k, T=T,
                           restart=restart, max_points=max_points, plot=plot, figures=figures,
                           progress=progress, ranks=ranks, point=point, comm=comm,
                           wall_start=wall_start)
    except BaseException as exc:
        if point is not None and comm.rank == 0:  # interrupted or failed: an honest aggregate
            settle(out, mapping, point, exc, plot, ex.id)
        raise


def _run_points(problem, out, ex, points, states, mapping, *, n, k, T, restart, max_points,
                plot, figures, progress, ranks, point, comm, wall_start) -> dict:
    """The points of this call (after the checks and the opening of the folder), and the
    record."""
    from damage_dolfinx.runtime.collective import classify, describe, mark
    from damage_dolfinx.runtime.runfolder import RunLive
    from damage_dolfinx.runtime.runner import run as run_one
    from damage_dolfinx.studies.sweep_folder import record
    size = comm.size
    if point is not None:
        pending = [] if states[point] == "completed" else [point]
        todo = pending
    else:
        pending = [i for i, s in enumerate(states) if s != "completed"]
        todo = pending[:max_points] if max_points else pending
    groups, color = size // ranks, comm.rank // ranks
    group = comm if ranks == size else MPI.COMM_SELF if ranks == 1 else \
        comm.Split(color, comm.rank)
    mine = todo[color::groups]
    relay, notice = Relay(comm), StopNotice(comm)
    if comm.rank == 0 and progress:
        if point is not None and not todo:
            print(f"[sweep {ex.id}] point {point} ({_describe(points[point])}) is already "
                  "completed: nothing to do", flush=True)
        elif point is not None:
            print(f"[sweep {ex.id}] point {point} of {len(points)} "
                  f"({_describe(points[point])}) on {size} rank(s)", flush=True)
        else:
            layout = f"{groups} group(s) of {ranks} rank(s)" if ranks > 1 else \
                f"{size} rank(s)"
            print(f"[sweep {ex.id}] {len(points)} points, {len(points) - len(pending)} finished, "
                  f"running {len(todo)} on {layout}", flush=True)
    failures, stopped = {}, None
    try:
        for i in mine:
            notice.check()  # another rank stopped on a signal: this one too
            values = points[i]
            folder = out / f"point_{i}"
            resume = restart and states[i] == "checkpoint"
            start = time.perf_counter()
            try:
                summary = point_outcome(
                    group, comm, [(folder, "run")] + ([(out, "sweep")] if point is None else []),
                    lambda: run_one(problem, folder, n=n, k=k, T=T, overrides=dict(values),
                                    progress=False, figures=figures, restart=resume,
                                    overwrite=not resume, comm=group,
                                    on_step=notice.check))
                status = summary["status"]
            except RunLive:
                if point is not None:
                    raise  # the one point asked for is live elsewhere: refused
                status = "live in another process, left to it"
            except Exception as exc:  # noqa: BLE001 - a point fails, the sweep goes on
                if classify(exc)[2] == "interrupted":
                    raise  # the sweep stops: every rank (below)
                if group.rank == 0:
                    mark(folder, exc)
                status = f"failed ({describe(exc)})"
                failures[i] = describe(exc)
            if progress and group.rank == 0:
                where = f"rank {comm.rank}" if ranks == 1 else \
                    f"ranks {comm.rank}-{comm.rank + ranks - 1}"
                relay.say(f"[sweep {ex.id}] point {i} ({_describe(values)}): {status} in "
                          f"{time.perf_counter() - start:.1f} s ({where})")
    except BaseException as exc:  # noqa: BLE001 - a signal stops every rank; others raise
        if classify(exc)[2] != "interrupted":
            raise  # (one rank only: collective.outcome ends the others)
        stopped = exc
        notice.send(exc)
    finally:
        if group not in (comm, MPI.COMM_SELF):
            group.Free()
    signum = notice.settle()  # every rank is here: stopped, or done with its points
    if signum or stopped is not None:
        relay.close()
        if stopped is not None:
            raise stopped
        from damage_dolfinx.runtime.signals import RECEIVED, SignalStop
        RECEIVED["signum"] = RECEIVED["signum"] or signum
        raise SignalStop(signum)  # its points ended before the stop: stopped all the same
    failures = {i: why for part in comm.allgather(failures) for i, why in part.items()}
    relay.close()
    info = {"ran": todo, "mpi_size": size, "ranks_per_point": ranks, "groups": groups,
            "point": point, "points_on_all_ranks": ranks == size and size > 1,
            "wall_time_s": time.perf_counter() - wall_start}
    summary = record(out, mapping, failures, info, plot, ex.id, comm)
    summary = dict(summary, failed_in_this_call=sorted(failures))
    if comm.rank == 0 and progress:
        failed = summary["failed"]
        print(f"[sweep {ex.id}] {summary['completed']}/{len(points)} points completed"
              + (f", {len(failed)} failed" if failed else "") + " in "
              f"{summary['wall_time_s']:.1f} s; table {out / 'sweep.csv'}", flush=True)
    return summary
