"""Eigensolved stability limits kept on disk, so that another process on the same mesh and data
(a restart, the points of a sweep, the levels of a convergence study, the next run of the same
example) does not repeat the eigensolves.

One small JSON file per result, named by the hash that the in-memory cache uses (the assembled
K_B, K, M, m_visc, the eigen method and tolerance: mesh, partition, material, contact and
Dirichlet rows all enter it; stability_bound.key), in

    $DAMAGE_DOLFINX_CACHE_DIR/stability/        if that variable is set (``off``: no disk cache)
    $XDG_CACHE_HOME/damage-dolfinx/stability/   else, if XDG_CACHE_HOME is an absolute path
    ~/.cache/damage-dolfinx/stability/          else

never in a run's folder. Rank 0 reads and writes, the other ranks get its answer. A file is
written to a temporary name in the same folder and renamed into place, so concurrent writers
(two jobs finishing the same eigensolve) and a kill leave either no file or a whole one. A file
that cannot be read, or whose content is not what was stored, is ignored (the eigensolve runs
and rewrites it), and so is one whose numbers do not agree with its key or with the cheap
bounds of the mesh and data (stability_bound.cached_problem, with a warning: an edited entry
is never believed); a folder that cannot be written only means no disk cache. Delete the folder
to clear the cache. FORMAT changes whenever the stored numbers would change for the same key.
"""
from __future__ import annotations

import json
import math
import os
import tempfile
from pathlib import Path

#: environment variable of the cache folder (``off`` disables the disk cache)
ENV = "DAMAGE_DOLFINX_CACHE_DIR"
#: version of the stored results (part of every key); 2: each result stores its own key, and
#: a result read back is verified against its key and the cheap bounds of the mesh and data
#: before it is used (stability_bound.cached_problem)
FORMAT = 2
#: the numbers a stored result must have
FIELDS = ("omega2_max", "k_max", "k_max_proportional_formula", "k_suggested")


def directory() -> Path | None:
    """The folder of the stored results (not created here); None when disabled."""
    value = os.environ.get(ENV)
    if value is not None:
        if value.strip().lower() in ("", "off"):
            return None
        return Path(value).expanduser() / "stability"
    xdg = os.environ.get("XDG_CACHE_HOME", "")
    base = Path(xdg) if xdg and os.path.isabs(xdg) else Path.home() / ".cache"
    return base / "damage-dolfinx" / "stability"


def _valid(value) -> bool:
    return (isinstance(value, dict) and value.get("format") == FORMAT
            and all(isinstance(value.get(f), (int, float)) and not math.isnan(value[f])
                    and value[f] > 0 for f in FIELDS))


def load(key: str, comm) -> dict | None:
    """The stored result of ``key`` (the same on every rank of ``comm``), or None."""
    value = None
    if comm.rank == 0:
        folder = directory()
        try:
            if folder is not None:
                value = json.loads((folder / f"{key}.json").read_text())
        except (OSError, ValueError):
            value = None
        if not _valid(value):
            value = None
    value = comm.bcast(value, root=0)
    if value is None:
        return None
    value.pop("format", None)
    return value


def save(key: str, value: dict, comm) -> bool:
    """Store ``value`` under ``key`` (rank 0, atomic rename); False where it could not."""
    ok = False
    if comm.rank == 0:
        folder = directory()
        try:
            if folder is not None:
                folder.mkdir(parents=True, exist_ok=True)
                text = json.dumps({**value, "format": FORMAT}, sort_keys=True)
                fd, tmp = tempfile.mkstemp(prefix=f".{key}.", suffix=".tmp", dir=folder)
                try:
                    with os.fdopen(fd, "w") as f:
                        f.write(text)
                    os.replace(tmp, folder / f"{key}.json")
                    ok = True
                finally:
                    if not ok:
                        os.unlink(tmp)
        except OSError:
            ok = False
    return bool(comm.bcast(ok, root=0))
