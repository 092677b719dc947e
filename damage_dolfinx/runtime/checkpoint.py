"""Checkpoint/restart of long runs, independent of the number of MPI ranks.

A checkpoint is ``checkpoint.npz``: the stepper's state Functions, gathered on rank 0 and keyed
by partition-independent dof positions, small NumPy arrays of solver state (the same on every
rank, e.g. whether a lagged factorisation is due for renewal), and its metadata (step, time, run
settings; ``__meta__``, also copied to ``checkpoint.json`` for people and scripts). Generations: a new checkpoint is
written completely to ``checkpoint.npz.tmp`` (fsync) before the previous one is renamed to
``checkpoint.prev.npz`` and the new one into place, so a run killed at any moment, or a full disk,
leaves at least one complete checkpoint; a restart takes the newest readable one (``latest``:
every array is read, so a truncated or empty file is detected) and says when it falls back. On
restart each rank finds its owned dofs among the saved keys by one vectorised sort (no point
search, no Python loop over dofs), so a run can resume on a different number of ranks.

Keys: the dof coordinates for continuous (P1) spaces; for discontinuous spaces (DG0 stresses of
2.4, DG1 memory of 2.3), whose dofs share coordinates, the coordinates plus the midpoint of the
dof's cell.
"""
from __future__ import annotations

import json
import os
import sys
from pathlib import Path

import numpy as np
from mpi4py import MPI

from damage_dolfinx import compat
from damage_dolfinx.runtime import io
from damage_dolfinx.core.parameters import InputError

FORMAT = "damage-dolfinx/checkpoint/v1"
#: statuses of a run that has nothing left to do (a larger T continues a "completed" one)
FINISHED = ("completed", "zeta_star_reached", "collapse")
#: keys are compared after rounding to this length (meshes of the thesis: 1e-3 .. 1e2 m)
KEY_RESOLUTION = 1e-9


def _owned_keys(f) -> np.ndarray:
    """(n_owned_blocks, 2 or 4; 3 or 6 in 3-D) partition-independent positions of f's owned dofs."""
    V = f.function_space
    n_owned = V.dofmap.index_map.size_local
    X = V.tabulate_dof_coordinates()[:n_owned, :V.mesh.topology.dim]  # 3-D: 3 coordinates
    if not compat.is_discontinuous(V):
        return X
    cell_dofs = compat.cell_dofs(V)
    dof_cell = np.empty(n_owned, dtype=np.int64)
    flat = cell_dofs.reshape(-1)
    owned = flat < n_owned  # DG dofs of owned cells are owned
    dof_cell[flat[owned]] = np.repeat(np.arange(cell_dofs.shape[0]), cell_dofs.shape[1])[owned]
    mid = compat.cell_midpoints(V.mesh)[dof_cell, :V.mesh.topology.dim]
    return np.hstack([X, mid])


def _values(f) -> np.ndarray:
    V = f.function_space
    return f.x.array.reshape(-1, V.dofmap.index_map_bs)[:V.dofmap.index_map.size_local]


#: newest first; the temporary file counts only if complete (a kill between the two renames)
GENERATIONS = ("checkpoint.npz", "checkpoint.prev.npz", "checkpoint.npz.tmp")


def save(out, state: dict, meta: dict, comm=MPI.COMM_WORLD):
    """Write the checkpoint of ``state`` (name -> Function) and ``meta`` (JSON-able), keeping
    the previous generation. A failed write (disk full) raises io.OutputError on every rank and
    leaves the earlier checkpoints as they were."""
    out = Path(out)
    gathered = {}
    for name, f in state.items():
        if isinstance(f, np.ndarray):  # solver state, the same on every rank
            gathered[name] = np.array(f)
            continue
        keys, vals = comm.gather(_owned_keys(f), root=0), comm.gather(_values(f), root=0)
        if comm.rank == 0:
            gathered[name + "__keys"], gathered[name] = np.concatenate(keys), np.concatenate(vals)
    text = io.strict_json({"format": FORMAT, **meta})
    gathered["__meta__"] = np.array(text)

    def write():
        if comm.rank != 0:
            return
        newest = out / GENERATIONS[0]
        io.atomic_write_bytes(out / GENERATIONS[2], io.npz_writer(gathered), fsync=True)
        # the complete new file exists: the previous generation can move aside
        if newest.exists():
            os.replace(newest, out / GENERATIONS[1])
        os.replace(out / GENERATIONS[2], newest)
        io.write_json(out / "checkpoint.json", json.loads(text))

    what = f"checkpoint.npz at step {meta.get('step')} (t = {meta.get('t', 0):.6g})"
    io.collective(comm, out, what, write)


def latest(out, comm=MPI.COMM_WORLD):
    """(file, meta) of the newest readable checkpoint in ``out``; a fallback to an older
    generation is announced on stderr (rank 0). Raises InputError if there is none."""
    result = _latest(Path(out)) if comm.rank == 0 else None
    path, meta, notes, error = comm.bcast(result, root=0)
    if error:
        raise InputError(error)
    if notes and comm.rank == 0:
        print(f"damage-dolfinx: {'; '.join(notes)}; restarting from {path.name} "
              f"(step {meta['step']})", file=sys.stderr, flush=True)
    return path, meta


def _latest(out: Path):
    notes = []
    for name in GENERATIONS:
        path = out / name
        if not path.exists():
            continue
        try:
            with np.load(path) as data:
                arrays = {key: data[key] for key in data.files}  # reads (CRC-checks) each
                meta = json.loads(str(arrays["__meta__"])) if "__meta__" in arrays else \
                    json.loads((out / "checkpoint.json").read_text())  # pre-generation format
        except Exception as exc:  # noqa: BLE001 - any unreadable file: try the next generation
            if name != GENERATIONS[2]:
                size = path.stat().st_size
                notes.append(f"{name} is unreadable ({type(exc).__name__}, {size} bytes)")
            continue
        if not isinstance(meta, dict) or meta.get("format") != FORMAT:
            notes.append(f"{name} is not a {FORMAT} checkpoint")
            continue
        problem = _problem(arrays, meta)
        if problem:
            notes.append(f"{name} {problem}")
            continue
        return path, meta, notes, None
    if not notes:
        return None, None, [], (f"cannot restart: no checkpoint in {str(out)!r} "
                                "(checkpoint.npz missing)")
    return None, None, [], f"cannot restart: no readable checkpoint in {str(out)!r} ({'; '.join(notes)})"


def _problem(arrays: dict, meta: dict):
    """What makes a readable checkpoint unusable (None: nothing): a value that is not finite,
    keys and values of different lengths, metadata without a whole step and a finite time."""
    step, t = meta.get("step"), meta.get("t")
    if isinstance(step, bool) or not isinstance(step, int) or step < 0:
        return f"has step = {step!r} in its metadata, not a whole number >= 0"
    if isinstance(t, bool) or not isinstance(t, (int, float)) or not np.isfinite(t):
        return f"has t = {t!r} in its metadata, not a finite number"
    for key, value in arrays.items():
        if key == "__meta__":
            continue
        # fields (the arrays with their dof positions) must be finite; solver state may hold
        # NaN on purpose (a 3.3 monitor before the first contact)
        if value.dtype.kind in "fc" and f"{key}__keys" in arrays and \
                not np.isfinite(value).all():
            return f"holds non-finite values (NaN or Inf) in {key!r}"
        if key.endswith("__keys"):
            field = arrays.get(key[:-len("__keys")])
            if field is None or value.ndim != 2 or value.shape[1] not in (2, 3, 4, 6) \
                    or len(field) != len(value):
                return (f"has {key!r} of shape {value.shape} for "
                        f"{None if field is None else field.shape} values")
    return None


def resume_point(out, settings, grid, previous, comm=MPI.COMM_WORLD, parameters=None):
    """(checkpoint file, its metadata) after checking it belongs to this run, or None when the
    run in ``out`` (``previous``: its summary or None) finished and this T adds no step (nothing
    to do). Raises InputError if it cannot be resumed."""
    finished = previous is not None and previous.get("status") in FINISHED
    try:
        path, meta = latest(out, comm)
    except InputError:
        if not finished or any((Path(out) / name).exists() for name in GENERATIONS):
            raise  # says which checkpoint file is unusable and why
        path, meta = None, {key: previous.get(key) for key in ("example", "n", "k")}
    for key, value in settings.items():
        if key in meta and meta.get(key) != value:
            raise InputError(f"cannot restart: the {'checkpoint' if path else 'run'} in "
                             f"{str(out)!r} has {key} = {meta.get(key)!r}, this run {value!r}")
    saved = meta.get("parameters") if path else (previous or {}).get("parameters")
    if parameters is not None and isinstance(saved, dict):
        now = json.loads(io.strict_json(parameters))
        changed = sorted(key for key in set(saved) | set(now) if saved.get(key) != now.get(key))
        if changed:
            key = changed[0]
            raise InputError(f"cannot restart: the {'checkpoint' if path else 'run'} in "
                             f"{str(out)!r} has {key} = {saved.get(key)!r}, this run "
                             f"{now.get(key)!r} (the model parameters differ)")
    if finished and (previous["status"] != "completed" or grid.num_steps <= previous["steps_done"]):
        return None
    if path is None:
        raise InputError(f"cannot continue the completed run in {str(out)!r} to T = {grid.T:g}: "
                         "it has no checkpoint (checkpoints were off)")
    if meta["step"] > grid.num_steps:
        raise InputError(f"cannot restart: the checkpoint is at t = {meta['t']}, beyond T = {grid.T}")
    return path, meta


def _match(saved: np.ndarray, local: np.ndarray) -> np.ndarray:
    """Index into ``saved`` of every row of ``local`` (rows equal after rounding)."""
    scale = KEY_RESOLUTION * max(1.0, float(np.abs(saved).max()) if saved.size else 1.0)
    q = np.rint(np.vstack([saved, local]) / scale).astype(np.int64)
    label = np.r_[np.zeros(len(saved), np.int64), np.ones(len(local), np.int64)]
    order = np.lexsort((label, *q.T[::-1]))  # by position, saved before local on ties
    position = np.empty_like(order)
    position[order] = np.arange(len(order))
    before = order[position[len(saved):] - 1]  # the row sorted just before each local row
    ok = (before < len(saved)) & np.all(q[before] == q[len(saved):], axis=1)
    if not ok.all():
        raise InputError("cannot restart: the checkpoint does not match this mesh "
                         f"({int((~ok).sum())} dofs without a saved value)")
    return before


def load(path, state: dict):
    """Set every Function (and NumPy array, in place) of ``state`` from the checkpoint file
    ``path`` (from ``latest``; any number of ranks); InputError naming the file for a field
    that is missing or has the wrong shape."""
    data = np.load(path)
    for name, f in state.items():
        if name not in data:
            raise InputError(f"cannot restart: {path.name} has no field {name!r}")
        if isinstance(f, np.ndarray):
            if data[name].shape != f.shape:
                raise InputError(f"cannot restart: {path.name} has {name!r} of shape "
                                 f"{data[name].shape}, this run {f.shape}")
            f[...] = data[name]
            continue
        if name + "__keys" not in data or data[name].reshape(len(data[name]), -1).shape[1] \
                != _values(f).shape[1] or data[name + "__keys"].shape[1] != \
                _owned_keys(f).shape[1]:
            raise InputError(f"cannot restart: {path.name} has {name!r} of shape "
                             f"{data[name].shape}, not that of this run's field")
        index = _match(data[name + "__keys"], _owned_keys(f))
        _values(f)[:] = data[name][index]
        f.x.scatter_forward()


# the fingerprint of a run (what defines it) lives in fingerprint.py; a resume checks it
from damage_dolfinx.runtime.fingerprint import fingerprint, verify_fingerprint  # noqa: E402,F401
