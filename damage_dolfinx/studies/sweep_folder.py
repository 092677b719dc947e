"""The sweep folder, shared by every process that runs points of the sweep (the ranks of one
command, or the separate jobs of a job array, each running ``point=I``).

* Opening (:func:`open_sweep`, rank 0, under the folder's lock ``.sweep.lock``): the first
  process to arrive writes ``points.json`` (the grid and what every point shares: problem,
  n, k, T), the manifest and ``summary.json``; a later one checks that its sweep is the same
  (another grid or problem is refused, nothing touched) and reads the state of every point.
* The per-point records are the points' own ``point_<i>/summary.json`` (written atomically by
  the run: status, final scalars); a failure that left no such record (a point refused before
  its run wrote one) is kept in the sweep's ``summary.json`` under ``errors``.
* Recording (:func:`record`, rank 0, under the same lock): ``sweep.csv``, ``sweep.png``, the
  manifest and ``summary.json`` are rebuilt from the per-point records and written atomically,
  so that they are consistent whatever order the points finish in and however many processes
  write the folder.
"""
from __future__ import annotations

import csv
import io as io_module
import itertools
import json
import sys
from pathlib import Path

from mpi4py import MPI

from damage_dolfinx.core.parameters import InputError

#: points.json schema
SCHEMA = "damage-dolfinx/sweep/v1"
#: summary columns of every point in sweep.csv, before the model's final scalars
STATUS_COLUMNS = ["status", "steps_done", "t_final", "wall_time_s"]
#: files of a sweep folder (besides point_<i>/, the manifest and the lock)
SWEEP_FILES = ("points.json", "sweep.csv", "sweep.png", "summary.json")


def describe_values(values: dict) -> str:
    return ", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}"
                     for k, v in values.items())


def point_state(folder: Path) -> str:
    """'completed', 'checkpoint' (interrupted, resumable), 'started' or 'new'."""
    try:
        status = json.loads((folder / "summary.json").read_text()).get("status")
    except (OSError, ValueError, AttributeError):
        status = None
    if status == "completed":
        return "completed"
    if (folder / "checkpoint.json").is_file():
        return "checkpoint"
    return "started" if folder.exists() else "new"


def open_sweep(out, mapping, point, comm) -> list:
    """Open the sweep folder ``out`` for the sweep ``mapping`` (points.json's content) under its
    lock (every rank gets rank 0's answer): refused (InputError, nothing touched) when it holds
    another sweep, a run, a study or files the package did not write; otherwise points.json,
    the manifest and summary.json are there afterwards. Returns the state of every point
    (``point_state``); ``point`` (an index): only that point's folder is checked (the others
    may be written by other jobs at this moment)."""
    from damage_dolfinx.runtime import runfolder
    # the checks first without the lock, so that a refused folder does not receive a lock file;
    # then again under it (another process may have written the folder in between). A refusal
    # of the first pass in a folder that already has the lock file may have seen another job of
    # the sweep half-way through opening it: it is decided again under the lock.
    try:
        runfolder.decided(comm, out, _open, Path(out), mapping, point, False)
    except InputError:
        shared = comm.bcast((Path(out) / runfolder.SWEEP_LOCK).is_file() if comm.rank == 0
                            else None)
        if not shared:
            raise
    with runfolder.shared_folder_lock(out, comm):
        return runfolder.decided(comm, out, _open, Path(out), mapping, point, True)


def _open(out: Path, mapping: dict, point, apply: bool) -> list:
    from damage_dolfinx.runtime.atomic import write_json
    existing = None
    if (out / "points.json").is_file():
        try:
            existing = json.loads((out / "points.json").read_text())
        except ValueError:
            existing = {}
        if not isinstance(existing, dict):
            existing = {}
    wanted = json.loads(json.dumps(mapping))
    # "shared" (what the points share) came later: a folder written before it is compared
    # without it
    keys = [key for key in wanted if key not in ("shared", "fingerprint") or existing is None
            or key in existing]
    if existing is not None and {key: existing.get(key) for key in keys} != \
            {key: wanted[key] for key in keys}:
        raise InputError(f"{str(out)!r} holds another sweep (a different problem, grid, n, k or "
                         "T in its points.json); choose another out folder")
    states = _claim_sweep(out, len(mapping["points"]), point, apply)
    if not apply:
        return states
    if existing is None:
        write_json(out / "points.json", mapping, MPI.COMM_SELF)
    summary = _read_summary(out)
    summary.update(schema=SCHEMA, case=mapping["case"], status="running",
                   points=len(mapping["points"]))
    write_json(out / "summary.json", summary, MPI.COMM_SELF)
    return states


def _read_summary(out: Path) -> dict:
    try:
        summary = json.loads((out / "summary.json").read_text())
    except (OSError, ValueError):
        return {}
    return summary if isinstance(summary, dict) and summary.get("schema") == SCHEMA else {}


def _claim_sweep(out: Path, count: int, point, apply=True) -> list:
    from damage_dolfinx.runtime import runfolder
    names = {f"point_{i}" for i in range(count)} | set(SWEEP_FILES)
    # one snapshot, in this order: the names present, then the manifest once. Another job of
    # the sweep writes the manifest before any other file of the sweep, so whatever it wrote by
    # the listing is named in the manifest read after it (reading the manifest twice could see
    # none, then one)
    present = {p.name for p in out.iterdir()}
    known = runfolder.read_manifest(out)
    # without a manifest: a run or a study written before manifests, told by its summary alone
    found = known[0] if known is not None else (runfolder._legacy(out) or (None,))[0]
    if found in ("run", "study"):
        what = {"run": "a run", "study": "a convergence study"}[found]
        raise InputError(f"{str(out)!r} holds {what}; a sweep needs a folder of its own: "
                         "choose another --out (nothing was touched)")
    if known is None:
        ours = set() if "points.json" not in present else \
            {n for n in present if n in names}  # a sweep written before manifests
    else:
        ours = known[1]
    others = {n for n in present - ours - {runfolder.MANIFEST} - {n + ".tmp" for n in ours}
              if not runfolder._ours(n, ())}
    if others:
        raise InputError(f"{str(out)!r} holds {runfolder._listing(others)}, not written by "
                         f"damage-dolfinx (not in its {runfolder.MANIFEST}): move them or "
                         "choose another --out (nothing was touched)")
    states = []
    for i in range(count):
        folder = out / f"point_{i}"
        if point is not None and i != point:
            states.append(point_state(folder))
            continue
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
        states.append(point_state(folder))
    if apply:
        runfolder.write_manifest(out, "sweep", names | (ours & present))
    return states


def record(out, mapping, failures, info, plot, label, comm) -> dict:
    """Rebuild ``sweep.csv``, ``sweep.png``, the manifest and ``summary.json`` from the
    per-point records, under the folder's lock (rank 0; every rank gets the summary).
    ``failures``: {point: why} of the points that failed in this call; ``info``: what this
    call adds to the summary."""
    from damage_dolfinx.runtime import runfolder
    summary = None
    if comm.rank == 0:
        with runfolder.shared_folder_lock(out, MPI.COMM_SELF):
            summary = _record(Path(out), mapping, failures, info, plot, label)
    return comm.bcast(summary, root=0)


def _record(out, mapping, failures, info, plot, label) -> dict:
    from damage_dolfinx.runtime import io, runfolder
    grid, count = mapping["grid"], len(mapping["points"])
    earlier = _read_summary(out).get("errors") or {}
    rows, scalars, errors = [], [], {}
    for p in mapping["points"]:
        i = p["index"]
        row = {"point": i, "folder": p["folder"], **p["values"]}
        try:
            s = json.loads((out / p["folder"] / "summary.json").read_text())
            if not isinstance(s, dict):
                s = {}
        except (OSError, ValueError):
            s = {}
        why = failures.get(i) if i in failures else earlier.get(str(i))
        status = "failed" if i in failures else (s.get("status") or
                                                 ("failed" if why else "pending"))
        if status == "failed":
            errors[str(i)] = why or s.get("error") or "see its summary.json"
        row.update({c: s.get(c, "") for c in STATUS_COLUMNS}, status=status)
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
        print(f"damage-dolfinx: warning: no plot: {plot!r} is not a final scalar of this "
              f"problem (known: {', '.join(scalars)})", file=sys.stderr, flush=True)
        plot = None
    if plot and done:
        io.collective(MPI.COMM_SELF, out, "sweep.png", plot_sweep, out / "sweep.png", done,
                      grid, plot, label)
    failed = sorted(int(i) for i in errors)
    live = [r["point"] for r in rows if r["status"] == "running" and _live(out / r["folder"])]
    status = "running" if live else "failed" if failed else \
        ("completed" if len(done) == count else "incomplete")
    known = runfolder.read_manifest(out)
    names = {f"point_{i}" for i in range(count)} | set(SWEEP_FILES)
    if known is None or not names <= known[1]:
        runfolder.write_manifest(out, "sweep", names | (known[1] if known else set()))
    summary = {"schema": SCHEMA, "case": mapping["case"], "status": status, "grid": grid,
               "points": count, "completed": len(done), "failed": failed, "errors": errors,
               **({"error": f"{len(failed)} of {count} points failed"} if failed else {}),
               "pending": [r["point"] for r in rows if r["status"] != "completed"],
               "live": live,
               "point_status": {str(r["point"]): r["status"] for r in rows},
               **info, "csv": "sweep.csv",
               "plot": "sweep.png" if plot and done else None}
    io.write_json(out / "summary.json", summary, MPI.COMM_SELF)
    return summary


def _live(folder: Path) -> bool:
    """A run holds ``folder``'s lock: its process (named in ``.lock``) is alive."""
    from damage_dolfinx.runtime.runfolder import _alive
    try:
        with open(folder / ".lock", "rb") as f:
            holder = f.readline().decode(errors="replace").split()
    except OSError:
        return False
    return len(holder) >= 4 and holder[0] == "pid" and _alive(holder[1], holder[3])


def settle(out, mapping, point, exc, plot, label):
    """A job of one point that stops on an exception (a signal, a failure): the point's own
    status first (``collective.mark``: only where the run recorded none), then the aggregate
    rebuilt from the per-point records (``_record``), so that the sweep's summary.json does
    not stay "running" after its last live job ended. One process (the job's rank 0); never
    raises (the exception being handled is what the caller reports)."""
    from damage_dolfinx.runtime import runfolder
    from damage_dolfinx.runtime.collective import mark
    try:
        if not isinstance(exc, runfolder.RunLive):  # (a live run there is another job's)
            mark(Path(out) / f"point_{point}", exc)
        with runfolder.shared_folder_lock(out, MPI.COMM_SELF):
            _record(Path(out), mapping, {}, {"point": point}, plot, label)
    except Exception:  # noqa: BLE001 - a full disk, a removed folder: the line still tells
        pass


def plot_sweep(path, rows, grid, scalar, label):
    """``scalar`` against the first swept parameter with several values, one line per
    combination of the others."""
    from damage_dolfinx.viz import figstyle
    return figstyle.styled(_plot_sweep)(path, rows, grid, scalar, label)


def _plot_sweep(path, rows, grid, scalar, label):
    """The axes name their quantities (parameter and scalar by what they are, with the
    symbol of the model's equations and the name to pass to ``--set``); a log x axis when
    the swept values span a decade or more; one line per combination of the other
    parameters, named in a legend under the axes (never over the points)."""
    from damage_dolfinx.viz import figstyle
    from damage_dolfinx.viz.figtext import PARAMETERS, parameter_label, scalar_label
    names = list(grid)
    x_name = next((name for name in names if len(grid[name]) > 1), names[0])
    others = [name for name in names if name != x_name]
    fig, ax = figstyle.plt().subplots(figsize=(5.6, 3.6))
    numeric = all(isinstance(v, (int, float)) for v in grid[x_name])

    def symbol(name):
        return PARAMETERS[name][1] if name in PARAMETERS else name

    lines = 0
    for combo in itertools.product(*(grid[name] for name in others)):
        sel = [r for r in rows if all(r[name] == v for name, v in zip(others, combo))]
        if not sel:
            continue
        order = grid[x_name]
        sel.sort(key=lambda r: order.index(r[x_name]))
        xs = [r[x_name] if numeric else str(r[x_name]) for r in sel]
        ax.plot(xs, [r[scalar] for r in sel], "o-", ms=5, lw=1.3,
                label=", ".join(f"{symbol(name)} = {v:g}" if isinstance(v, float)
                                else f"{symbol(name)} = {v}"
                                for name, v in zip(others, combo)) or None)
        lines += 1
    if numeric and min(grid[x_name]) > 0 and max(grid[x_name]) >= 10 * min(grid[x_name]):
        ax.set_xscale("log")
    if numeric:
        ax.set_xticks(sorted(grid[x_name]))  # a tick at every swept value
        ax.set_xticks([], minor=True)
        ax.xaxis.set_major_formatter(figstyle.ticker().FuncFormatter(lambda v, _: f"{v:g}"))
    ax.set_xlabel(parameter_label(x_name))
    ax.set_ylabel(scalar_label(scalar))
    ax.grid(True, alpha=0.3)
    if others:
        figstyle.legend_below(ax, ncol=min(3, max(1, lines)))
    figstyle.save(fig, path, title=f"{label}: final {scalar_label(scalar).split('  [')[0]} "
                                   f"over the sweep ({len(rows)} points)")
