"""The one validation layer of the public API (and of the command line, which maps onto it),
first half: the scalars and the arguments of the entry points, each checked by its name
(``ARGUMENTS``); a Problem's own data are checked in :mod:`damage_dolfinx.problem.checks`.
Every argument of :class:`~damage_dolfinx.Problem`, :func:`~damage_dolfinx.run`,
:func:`~damage_dolfinx.converge`, :func:`~damage_dolfinx.sweep`,
:func:`~damage_dolfinx.read_mesh` and :func:`~damage_dolfinx.from_gmsh` is checked here for its
type, its range and, once the mesh exists, its shape against the mesh dimension (loads and
damage laws are evaluated symbolically in UFL, nothing is assembled). A failure raises
:class:`~damage_dolfinx.InputError` naming the argument and what was expected; the checks are
deterministic, so every rank refuses alike, before any file is written.

NumPy scalars are accepted wherever a number is (``T=np.int64(1)``); booleans are not numbers.
"""
from __future__ import annotations

import math
import numbers
import sys
from pathlib import Path

import numpy as np

from damage_dolfinx.core.errors import InputError

#: the smallest normal double: a nonzero number below it has lost its precision (underflow)
TINY = sys.float_info.min

#: parameters for which inf is meaningful ("no truncation"); every other number must be finite
INFINITE_ALLOWED = frozenset({"L_trunc"})

#: the largest sweep grid (points); larger grids are refused before any work
MAX_SWEEP_POINTS = 10000


# ---------------------------------------------------------------------------- scalars
def _shown(value) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def is_real(value) -> bool:
    return isinstance(value, (numbers.Real, np.floating, np.integer)) and \
        not isinstance(value, (bool, np.bool_))


def real(name, value, *, low=None, high=None, low_open=False, allow_none=False,
         what="a number") -> float | None:
    """``value`` as a finite float in the range, or InputError naming ``name``."""
    if value is None and allow_none:
        return None
    if not is_real(value):
        raise InputError(f"{name} must be {what}, got {_shown(value)} "
                         f"({type(value).__name__})")
    v = float(value)
    if not math.isfinite(v):
        raise InputError(f"{name} must be a finite number, got {v}")
    if 0.0 < abs(v) < TINY:
        raise InputError(f"{name} = {v:g} underflows (below {TINY:.3g}, the smallest normal "
                         "number): no time, size or datum is that small")
    if low is not None and (v <= low if low_open else v < low):
        raise InputError(f"{name} must be {'>' if low_open else '>='} {low:g}, got {v:g}")
    if high is not None and v > high:
        raise InputError(f"{name} must be <= {high:g}, got {v:g}")
    return v


def positive(name, value, allow_none=False):
    return real(name, value, low=0.0, low_open=True, allow_none=allow_none,
                what="a positive number")


def whole(name, value, *, low=1, allow_none=False) -> int | None:
    """``value`` as an int >= ``low`` (a float with a whole value is not accepted: a level or
    a count is a whole number)."""
    if value is None and allow_none:
        return None
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Integral,
                                                                      np.integer)):
        raise InputError(f"{name} must be a whole number >= {low}, got {_shown(value)} "
                         f"({type(value).__name__})")
    if int(value) < low:
        raise InputError(f"{name} must be a whole number >= {low}, got {int(value)}")
    return int(value)


def flag(name, value) -> bool:
    if not isinstance(value, (bool, np.bool_)):
        raise InputError(f"{name} must be True or False, got {_shown(value)} "
                         f"({type(value).__name__})")
    return bool(value)


def text(name, value, allow_none=False) -> str | None:
    if value is None and allow_none:
        return None
    if not isinstance(value, str) or not value:
        raise InputError(f"{name} must be a non-empty text, got {_shown(value)}")
    return value


def levels(name, values, cast) -> list:
    """A non-empty list of levels (``cast(name[i], v)``); a bare number is refused with the
    list form as the expected one."""
    if isinstance(values, (str, bytes, dict)) or not hasattr(values, "__iter__"):
        raise InputError(f"{name} must be a list, e.g. {name}=[{_shown(values)}], got "
                         f"{_shown(values)} ({type(values).__name__})")
    values = list(values)
    if not values:
        raise InputError(f"{name} must list at least one value")
    out = [cast(f"{name}[{i}]", v) for i, v in enumerate(values)]
    if len(set(out)) != len(out):
        raise InputError(f"{name} lists a value twice: {out}")
    return out


def path(name, value, allow_none=False):
    if value is None and allow_none:
        return None
    if not isinstance(value, (str, Path)) or not str(value):
        raise InputError(f"{name} must be a folder path (text), got {_shown(value)} "
                         f"({type(value).__name__})")
    return value


# ---------------------------------------------------------------------------- mesh files
def mesh_path_problem(p: Path):
    """What is wrong with a mesh file path before it is opened (None: nothing)."""
    if p.is_dir():
        return "is a folder, not a gmsh .msh file"
    if p.is_symlink() and not p.exists():
        return "is a dangling symbolic link"
    if not p.exists():
        return "does not exist"
    if not p.is_file():
        return "is not a regular file"
    return None


# ---------------------------------------------------------------------------- entry points
def communicator(name, value):
    from mpi4py import MPI
    if not isinstance(value, MPI.Comm):
        raise InputError(f"{name} must be an MPI communicator (e.g. MPI.COMM_WORLD), got "
                         f"{_shown(value)} ({type(value).__name__})")
    return value


def callback(name, value, signature="(step)"):
    if value is not None and not callable(value):
        raise InputError(f"{name} must be a function {signature} or None, got {_shown(value)} "
                         f"({type(value).__name__})")
    return value


def _maybe(check):
    return lambda name, value: check(name, value, allow_none=True)


def changes(name, value):
    """A run's changes to the problem's data: a dict of names to values, or None."""
    if value is not None and (not isinstance(value, dict) or
                              not all(isinstance(key, str) and key for key in value)):
        raise InputError(f"{name} must be a dict of parameter names to values, got "
                         f"{_shown(value)} ({type(value).__name__})")
    return None if value is None else dict(value)


def seconds(name, value):
    """A wall-time interval: a finite number >= 0 (0: never)."""
    if not is_real(value) or not math.isfinite(float(value)) or float(value) < 0:
        raise InputError(f"{name} must be a finite number >= 0 (0: none), got {_shown(value)}")
    return real(name, value, low=0.0)  # and not an underflow


def reference_layout(name, value):
    """Where a convergence study runs its reference: 1 (rank 0 alone), "all", or None."""
    if value is not None and (isinstance(value, bool) or value not in (1, "all")):
        raise InputError(f"{name} must be 1, 'all' or None, got {_shown(value)}")
    return value


def mesh_file_path(name, value):
    if value is None:
        return None
    if not isinstance(value, (str, Path)) or not str(value):
        raise InputError(f"{name} must be a gmsh .msh file path, got {_shown(value)}")
    return value


#: every keyword argument of the entry points (run, steps, converge, sweep, read_mesh,
#: from_gmsh), checked by its name: one rule per name, whichever function takes it
def petsc_options(name, value):
    """PETSc options of a call: the checks of the command line's options (names; the values on
    throwaway solvers when the call starts: petsc_options.scoped)."""
    from damage_dolfinx.core.petsc_names import normalised
    return normalised(value)


ARGUMENTS = {
    "petsc_options": petsc_options,
    "out": path, "n": _maybe(whole), "k": _maybe(positive), "T": _maybe(positive),
    "restart": flag, "overwrite": flag, "progress": flag, "figures": flag,
    "checkpoint_every": _maybe(whole), "max_points": _maybe(whole),
    "h": _maybe(positive), "write_every": _maybe(whole), "history_every": _maybe(whole),
    "checkpoint_seconds": seconds, "overrides": changes, "mesh_file": mesh_file_path,
    "reference_ranks": reference_layout,
    "plot": _maybe(text), "comm": communicator, "on_step": callback,
    "ref_n": _maybe(whole), "ref_k": _maybe(positive),
    "ranks_per_point": _maybe(whole),
    "point": lambda name, value: whole(name, value, low=0, allow_none=True),
}


#: the defaults of the public entries (run, steps, converge, sweep) and of the command line's
#: options of the same name, in one place: nothing written earlier is replaced unless asked
DEFAULTS = {"restart": False, "overwrite": False, "progress": True, "figures": True,
            "checkpoint_every": None}


def arguments(**given) -> dict:
    """``given`` with each value checked (and normalised: NumPy scalars to Python) by the rule
    of its name in ARGUMENTS; InputError naming the first argument that fails."""
    return {name: ARGUMENTS[name](name, value) for name, value in given.items()}


def check_run(out=None, comm=None, **given):
    """The arguments of run() and steps() besides the problem (the command line's run passes
    the same ones: this is the only place they are checked)."""
    extra = {} if comm is None else {"comm": comm}
    return arguments(out=out, **given, **extra)


def check_converge(n, k, ref_n, ref_k, T, restart=False, overwrite=False, progress=True,
                   out=None, comm=None):
    """The levels of converge(): lists of whole n and positive k, the reference's, T, and its
    flags (its folder and communicator when given)."""
    extra = {} if comm is None else {"comm": comm}
    if out is not None:
        extra["out"] = out
    rest = arguments(ref_n=ref_n, ref_k=ref_k, T=T, restart=restart, overwrite=overwrite,
                     progress=progress, **extra)
    return (None if n is None else levels("n", n, whole),
            None if k is None else levels("k", k, positive), rest["ref_n"], rest["ref_k"],
            rest["T"], rest["restart"], rest["overwrite"])


def check_sweep(grid, n, k, T, restart, max_points, plot, figures, progress, out=None,
                comm=None):
    """The arguments of sweep() besides the problem and the grid's values (check_grid)."""
    if isinstance(grid, dict) and grid:
        sizes = [len(v) if hasattr(v, "__len__") and not isinstance(v, (str, bytes)) else 1
                 for v in grid.values()]
        total = math.prod(sizes)
        if total > MAX_SWEEP_POINTS:
            raise InputError(f"the grid has {total:.3g} points ({' x '.join(map(str, sizes))}), "
                             f"more than {MAX_SWEEP_POINTS}: split it into several sweeps")
    extra = {} if comm is None else {"comm": comm}
    arguments(out=out, **extra)
    return arguments(n=n, k=k, T=T, restart=restart, max_points=max_points, plot=plot,
                     figures=figures, progress=progress)


def check_mesh_reading(path_value, dim, comm=None):
    """read_mesh's arguments: a path to a regular file, a dimension 2 or 3 (or None), a
    communicator."""
    if not isinstance(path_value, (str, Path)) or not str(path_value):
        raise InputError(f"read_mesh: path must be a file path, got {_shown(path_value)}")
    check_dim(dim)
    if comm is not None:
        communicator("comm", comm)
    problem = mesh_path_problem(Path(path_value))
    if problem:
        raise InputError(f"mesh file {str(path_value)!r} {problem}")


def check_dim(dim):
    if dim is not None and (not is_real(dim) or int(dim) != dim or int(dim) not in (2, 3)):
        raise InputError(f"dim must be 2, 3 or None, got {_shown(dim)}")


def cell_types_problem(gmsh, d):
    """One cell type only (DOLFINx meshes have one; a mixed file would crash the reader)."""
    types = gmsh.model.mesh.getElementTypes(d)
    if len(types) > 1:
        names = [gmsh.model.mesh.getElementProperties(t)[0] for t in types]
        return (f"it mixes cell types ({', '.join(names)}); a mesh needs one cell type "
                "(gmsh: Mesh.RecombineAll 0 for triangles, or recombine every surface)")
    return None


def limit(name, value, source="") -> float:
    """A stability limit (k_max) a model or a cache gives: a positive number or math.inf (no
    limit); NaN, a negative number, zero or a non-number is the model's error, refused (a NaN
    limit would let every k through: k > NaN is False)."""
    where = f" ({source})" if source else ""
    if not is_real(value):
        raise InputError(f"{name}{where} must be a number, got {_shown(value)} "
                         f"({type(value).__name__})")
    v = float(value)
    if math.isnan(v) or v <= 0 or (0 < v < TINY):
        raise InputError(f"{name}{where} must be a positive number or inf (no limit), got {v}: "
                         "the stability limit cannot be checked")
    return v


def number_like(old, value, key):
    """A parameter's new value of the type of its default: a bool is not a number and a number
    not a bool (E=True would run with E = 1); a number is finite (inf only where meaningful)
    and does not underflow. Strings are read by parameters._coerce."""
    if isinstance(old, bool) and is_real(value):
        raise InputError(f"parameter {key} is a flag (True or False), got {_shown(value)}")
    if is_real(old) and isinstance(value, (bool, np.bool_)):
        raise InputError(f"parameter {key} is a number, got {value!r} (a bool is not a number)")
    if is_real(old) and not isinstance(value, str) and not is_real(value) and \
            not callable(value):
        raise InputError(f"parameter {key} is a number, got {_shown(value)} "
                         f"({type(value).__name__})")
    if is_real(value):
        v = float(value)
        if math.isnan(v) or (math.isinf(v) and key not in INFINITE_ALLOWED):
            raise InputError(f"parameter {key} must be a finite number, got {v}")
        if 0.0 < abs(v) < TINY:
            raise InputError(f"parameter {key} = {v:g} underflows (below {TINY:.3g})")
    return value


def claims_problem(gmsh, d):
    """What a gmsh model of dimension ``d`` claims and does not hold (rank 0; None: nothing):

    * its nodes span only ``d`` coordinates: a 2-D mesh lies in the x-y plane (one in the x-z
      plane would be read as a degenerate 2-D mesh, its y all equal);
    * every cell belongs to a physical group of dimension ``d`` (an untagged cell is left out
      of the mesh DOLFINx builds, or crashes PETSc);
    * the cells are first order (the package's spaces and outputs are of linear geometry)."""
    _, coords, _ = gmsh.model.mesh.getNodes()
    xyz = np.asarray(coords, dtype=float).reshape(-1, 3)
    if len(xyz):
        span = xyz.max(axis=0) - xyz.min(axis=0)
        scale = max(float(span.max()), 1e-300)
        if d == 2 and span[2] > 1e-10 * scale:
            flat = [("x", "y", "z")[i] for i in range(3) if span[i] <= 1e-10 * scale]
            plane = "-".join(a for a in "xyz" if a not in flat)
            where = f" (its {flat[0]} is constant: the {plane} plane)" if flat else ""
            return (f"it is a 2-D mesh whose nodes span z as well{where}: a 2-D problem is in "
                    "the x-y plane (rotate the geometry there, or mesh it in 3-D)")
        if d == 2 and span[0] <= 1e-10 * scale or d == 2 and span[1] <= 1e-10 * scale:
            return "it is a 2-D mesh whose nodes lie on one line (no area)"
    for t in gmsh.model.mesh.getElementTypes(d):
        name, _, order = gmsh.model.mesh.getElementProperties(t)[:3]
        if order != 1:
            return (f"its cells are of order {order} ({name}); only first-order cells are "
                    "supported (gmsh: Mesh.ElementOrder 1)")
    tagged = {tag for _, group in gmsh.model.getPhysicalGroups(d)
              for tag in gmsh.model.getEntitiesForPhysicalGroup(d, group)}
    untagged, total = 0, 0
    for _, entity in gmsh.model.getEntities(d):
        count = sum(len(e) for e in gmsh.model.mesh.getElements(d, entity)[1])
        total += count
        if entity not in tagged:
            untagged += count
    cell_nodes = np.unique(np.concatenate([np.asarray(n, dtype=np.int64) for n in
                                           gmsh.model.mesh.getElements(d)[2]] or [[]]))
    loose = 0
    for _, group in gmsh.model.getPhysicalGroups(d - 1):
        for entity in gmsh.model.getEntitiesForPhysicalGroup(d - 1, group):
            for nodes in gmsh.model.mesh.getElements(d - 1, entity)[2]:
                loose += int(np.sum(~np.isin(np.asarray(nodes, dtype=np.int64), cell_nodes)))
    if loose:
        return (f"tagged boundary facets have {loose} node(s) of no cell: cells were left out "
                f"(a {'surface' if d == 2 else 'volume'} in no physical group is not saved); "
                f"tag every cell (gmsh: Physical {'Surface' if d == 2 else 'Volume'} over "
                f"every {'surface' if d == 2 else 'volume'})")
    if untagged:
        part = "surface" if d == 2 else "volume"
        return (f"{untagged} of its {total} cells belong to no physical {part}: tag every cell "
                f"(gmsh: Physical {part.capitalize()} over every {part})")
    return None
