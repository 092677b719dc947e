"""What a convergence study's restart checks: its settings (example, reading, levels, T,
parameters) and, at every mesh level of the family (the reference's and each coarse n), the
same run fingerprint a run's restart checks (runtime/fingerprint.py: mesh, loads and law by a
canonical hash of their UFL, initial damage, boundary parts, irreversibility, reading, model
data). Any difference refuses the restart with one line naming it, before any file is written.
"""
from __future__ import annotations

import json

from damage_dolfinx.core.parameters import InputError
from damage_dolfinx.runtime.fingerprint import ITEMS, first_difference, fingerprint

SCHEMA = "damage-dolfinx/convergence/v1"


def level_fingerprints(ex, comm, levels, k, T, overrides) -> dict:
    """{str(n): fingerprint} of the family at each level n (the mesh and data built on all the
    study's ranks, no solver set up; the fingerprint is partition-independent)."""
    return {str(n): fingerprint(ex, ex.problem_data(comm, n=n, k=k, T=T, overrides=overrides))
            for n in levels}


def previous_study(out, comm):
    """The summary.json of a study in ``out`` (None: none, or not a study's)."""
    result = None
    if comm.rank == 0:
        try:
            result = json.loads((out / "summary.json").read_text())
        except (OSError, ValueError):
            result = None
        if not isinstance(result, dict) or result.get("schema") != SCHEMA:
            result = None
    return comm.bcast(result, root=0)


def outputs_intact(out, previous, comm) -> bool:
    """Whether the completed study in ``out`` still has its outputs as it wrote them (a restart
    with nothing to do trusts them; else the study runs again and rewrites them): every file of
    its manifest present, errors.csv whole (a header and one row of as many columns per error
    in the summary), the others non-empty. Rank 0 looks; every rank gets the answer."""
    intact = None
    if comm.rank == 0:
        try:
            files = json.loads((out / "manifest.json").read_text()).get("files", [])
            rows = (out / "errors.csv").read_text().splitlines()
            intact = (len(rows) == 1 + len(previous.get("errors") or [])
                      and len({row.count(",") for row in rows}) == 1
                      and all((out / name).stat().st_size > 0 for name in files))
        except (OSError, ValueError, AttributeError, TypeError):
            intact = False
    return comm.bcast(intact, root=0)


def check_restart(previous, settings, out, ref_n):
    """InputError naming the first setting, or at the first level the first fingerprint item,
    that differs between the study in ``out`` (its summary ``previous``) and this one. A summary
    written before fingerprints were recorded is compared on its settings."""
    for key, value in settings.items():
        if key == "fingerprints":
            continue
        if previous.get(key) != value:
            raise InputError(f"cannot restart: the study in {str(out)!r} has {key} = "
                             f"{previous.get(key)!r}, this study {value!r}; choose another out "
                             "folder (or overwrite=True) to run it")
    saved = previous.get("fingerprints")
    if not isinstance(saved, dict):
        return
    for level, now in settings.get("fingerprints", {}).items():
        differ = first_difference(saved.get(level), now)
        if differ:
            key, was, is_ = differ
            where = f"the reference mesh n = {level}" if level == str(ref_n) else \
                f"the level n = {level}"
            raise InputError(f"cannot restart: {ITEMS[key]} changed since the study in "
                             f"{str(out)!r} at {where} (study: {was!r}, this study: {is_!r}); "
                             "choose another out folder (or overwrite=True) to run it")
