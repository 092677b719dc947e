"""Checkpoint/restart of long runs, independent of the number of MPI ranks.

A checkpoint is ``checkpoint.npz`` (the stepper's state Functions, gathered on rank 0 and keyed
by partition-independent dof positions) plus ``checkpoint.json`` (step, time, run settings). Both
are written atomically (temporary file + rename), so a run killed at any moment leaves the last
complete checkpoint. On restart each rank finds its owned dofs among the saved keys by one
vectorised sort (no point search, no Python loop over dofs), so a run can resume on a different
number of ranks.

Keys: the dof coordinates for continuous (P1) spaces; for discontinuous spaces (DG0 stresses of
2.4, DG1 memory of 2.3), whose dofs share coordinates, the coordinates plus the midpoint of the
dof's cell.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
from mpi4py import MPI

from . import compat
from .parameters import InputError

FORMAT = "damage-dolfinx/checkpoint/v1"
#: keys are compared after rounding to this length (meshes of the thesis: 1e-3 .. 1e2 m)
KEY_RESOLUTION = 1e-9


def _owned_keys(f) -> np.ndarray:
    """(n_owned_blocks, 2 or 4) partition-independent positions of f's owned dofs."""
    V = f.function_space
    n_owned = V.dofmap.index_map.size_local
    X = V.tabulate_dof_coordinates()[:n_owned, :2]
    if "Discontinuous" not in V.ufl_element().family():
        return X
    cell_dofs = compat.cell_dofs(V)
    dof_cell = np.empty(n_owned, dtype=np.int64)
    flat = cell_dofs.reshape(-1)
    owned = flat < n_owned  # DG dofs of owned cells are owned
    dof_cell[flat[owned]] = np.repeat(np.arange(cell_dofs.shape[0]), cell_dofs.shape[1])[owned]
    mid = compat.cell_midpoints(V.mesh)[dof_cell, :2]
    return np.hstack([X, mid])


def _values(f) -> np.ndarray:
    V = f.function_space
    return f.x.array.reshape(-1, V.dofmap.index_map_bs)[:V.dofmap.index_map.size_local]


def save(out, state: dict, meta: dict, comm=MPI.COMM_WORLD):
    """Write the checkpoint of ``state`` (name -> Function) and ``meta`` (JSON-able)."""
    out = Path(out)
    gathered = {}
    for name, f in state.items():
        keys, vals = comm.gather(_owned_keys(f), root=0), comm.gather(_values(f), root=0)
        if comm.rank == 0:
            gathered[name + "__keys"], gathered[name] = np.concatenate(keys), np.concatenate(vals)
    if comm.rank == 0:
        tmp = out / "checkpoint.tmp.npz"
        np.savez(tmp, **gathered)
        os.replace(tmp, out / "checkpoint.npz")
        tmp_json = out / "checkpoint.json.tmp"
        tmp_json.write_text(json.dumps({"format": FORMAT, **meta}, indent=2) + "\n")
        os.replace(tmp_json, out / "checkpoint.json")
    comm.barrier()


def read_meta(out) -> dict:
    path = Path(out) / "checkpoint.json"
    if not path.is_file():
        raise InputError(f"cannot restart: no checkpoint in {str(out)!r} (checkpoint.json missing)")
    meta = json.loads(path.read_text())
    if meta.get("format") != FORMAT:
        raise InputError(f"cannot restart: {path} is not a {FORMAT} checkpoint")
    return meta


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


def load(out, state: dict):
    """Set every Function of ``state`` from the checkpoint in ``out`` (any number of ranks)."""
    data = np.load(Path(out) / "checkpoint.npz")
    for name, f in state.items():
        if name not in data:
            raise InputError(f"cannot restart: the checkpoint has no field {name!r}")
        index = _match(data[name + "__keys"], _owned_keys(f))
        _values(f)[:] = data[name][index]
        f.x.scatter_forward()
