"""The way a run takes through the package, measured by running it: every call into a module of
the package is recorded from the entry point (``dd.run`` or the command line's ``run``) until
the first call of a PETSc solve (``KSP.solve`` / ``SNES.solve``); the modules entered (rooms)
and the calls that go from a lower floor to a higher one (climbs back up; floors: tests/layers.py)
are counted. A call of a module's own functions stays in its room.

    python benchmarks/structure/walk.py            # both entries, on 2.2-ex1 (n = 4, two steps)

The floors of modules that moved into the layers are looked up under their new names
(``OLD_NAMES``), so that the same command measures an older checkout too.
"""
from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests"))
import layers  # noqa: E402

#: modules of earlier layouts -> the folder they live in now
OLD_NAMES = {"errors": "core", "parameters": "core", "departures": "core", "validation": "core",
             "validation_problem": "problem", "validation_scalars": "problem",
             "blocks": "models", "laws": "models", "problem": "problem",
             "description": "problem", "meshes": "problem", "workflow": "api",
             "results": "api"}


class Stop(Exception):
    pass


def floor(module: str) -> int:
    parts = module.split(".")
    folder = parts[1] if len(parts) > 1 else ""
    if len(parts) == 2 and folder in OLD_NAMES:  # a loose module of an earlier layout
        folder = OLD_NAMES[folder]
    return layers.floor_of(folder)


def walk(entry):
    """(rooms entered in order, climbs) of ``entry()`` up to the first PETSc solve."""
    from petsc4py import PETSc
    rooms, climbs, stack = [], 0, []
    solves = {PETSc.KSP.solve, PETSc.SNES.solve}

    def profile(frame, event, arg):
        nonlocal climbs
        if event == "c_call" and arg in solves:
            raise Stop
        if event != "call":
            return
        module = frame.f_globals.get("__name__", "")
        caller = frame.f_back.f_globals.get("__name__", "") if frame.f_back else ""
        if not module.startswith("damage_dolfinx"):
            return
        if module not in rooms:
            rooms.append(module)
        if caller.startswith("damage_dolfinx") and caller != module and \
                floor(module) > floor(caller):
            climbs += 1
            stack.append((caller, module))

    sys.setprofile(profile)
    try:
        entry()
    except Stop:
        pass
    finally:
        sys.setprofile(None)
    return rooms, climbs, stack


def main():
    os.environ.setdefault("MPLBACKEND", "Agg")
    import damage_dolfinx as dd
    out = Path(tempfile.mkdtemp())
    args = dict(n=4, k=0.002, T=0.004)
    entries = {
        "dd.run(\"2.2-ex1\", ...)": lambda: dd.run("2.2-ex1", out / "api", progress=False,
                                                   figures=False, **args),
        "damage-dolfinx run 2.2-ex1": lambda: __import__("damage_dolfinx.cli").cli.main(
            ["run", "2.2-ex1", "--n", "4", "--k", "0.002", "--T", "0.004", "--quiet",
             "--no-figures", "--out", str(out / "cli")]),
    }
    for name, entry in entries.items():
        rooms, climbs, pairs = walk(entry)
        floors = sorted({floor(m) for m in rooms})
        print(f"{name}: {len(rooms)} rooms on {len(floors)} floors before the first solve, "
              f"{climbs} climbs back up")
        for a, b in pairs:
            print(f"    climb: {a} -> {b}")


if __name__ == "__main__":
    main()
