"""The way a run takes through the package, measured by running it: every call into a module of
the package is recorded from the entry point (``dd.run`` or the command line's ``run``) until
the first call of a PETSc solve (``KSP.solve`` / ``SNES.solve``); the modules entered (rooms)
and the calls that go from a lower floor to a higher one through an import (climbs back up;
floors: tests/layers.py) are counted. A call of a module's own functions stays in its room; a
call of an object handed down (a Problem's property, a user's load, a model's sub-step called by
the loop) goes where the object was made, not through an import, and is no climb.

    python tests/walk.py            # both entries, on 2.2-ex1 (n = 4, two steps)

The floors of modules that moved into the layers are looked up under their new names
(``OLD_NAMES``), so that the same command measures an older checkout too.
"""
from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import layers  # noqa: E402
from layers import OLD_NAMES  # noqa: E402  (modules of earlier layouts -> their folder now)


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
    imports = {(a, b) for a, b, _ in layers.edges()}
    rooms, climbs, stack = [], 0, []
    solves = {PETSc.KSP.solve, PETSc.SNES.solve}

    def profile(frame, event, arg):
        nonlocal climbs
        if event == "c_call" and arg in solves:
            raise Stop
        if event != "call" or frame.f_code.co_name == "<module>":  # an import is no call
            return
        module = frame.f_globals.get("__name__", "")
        caller = frame.f_back.f_globals.get("__name__", "") if frame.f_back else ""
        if not module.startswith("damage_dolfinx"):
            return
        if module not in rooms:
            rooms.append(module)
        if caller.startswith("damage_dolfinx") and caller != module and \
                floor(module) > floor(caller) and (caller, module) in imports:
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


ENTRIES = {
    "api": 'dd.run("2.2-ex1", ...)',
    "cli": "damage-dolfinx run 2.2-ex1",
}


def entry_of(name, out):
    import damage_dolfinx as dd
    if name == "api":
        return lambda: dd.run("2.2-ex1", out, n=4, k=0.002, T=0.004, progress=False,
                              figures=False)
    from damage_dolfinx import cli
    return lambda: cli.main(["run", "2.2-ex1", "--n", "4", "--k", "0.002", "--T", "0.004",
                             "--quiet", "--no-figures", "--out", str(out)])


def main():
    """Each entry in a process of its own (so that neither inherits the other's imports)."""
    import subprocess
    os.environ.setdefault("MPLBACKEND", "Agg")
    if len(sys.argv) > 1:
        name = sys.argv[1]
        rooms, climbs, pairs = walk(entry_of(name, Path(tempfile.mkdtemp()) / "run"))
        floors = sorted({floor(m) for m in rooms})
        print(f"{ENTRIES[name]}: {len(rooms)} rooms on {len(floors)} floors before the first "
              f"solve, {climbs} climbs back up")
        for a, b in sorted(set(pairs)):
            print(f"    climb: {a} -> {b} ({pairs.count((a, b))}x)")
        return
    for name in ENTRIES:
        subprocess.run([sys.executable, __file__, name], check=True)


if __name__ == "__main__":
    main()
