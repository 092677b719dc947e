"""The fingerprint of a run: everything that defines it besides its time grid and parameters
(those are compared as settings), checked by every resume (a run's restart, a sweep point's,
each level of a convergence study's).

Each item is partition-independent and canonical, so the same problem gives the same
fingerprint on any number of ranks, under any Python hash seed, whatever else the process made
before it. Loads and laws are compared by a canonical hash of the UFL they build, not by UFL's
own signature: UFL orders the operands of a sum or a product by the text of their terminals,
in which a constant carries its creation count (``Constant(..., 13)`` sorts before
``Constant(..., 6)``), so the same code gave another signature in a process that had made more
UFL objects before. Here

    hash(terminal) = its kind, shape and rank among the terminals of its kind by creation
                     order (constants, functions, labels, indices); numbers by value;
                     geometric quantities by name (the mesh is its own item);
    hash(operator) = its type and its operands' hashes, sorted for a sum or a product,

plus the values UFL's signature leaves out: those of constants and a digest of functions'.
Nodal data (the mesh's node coordinates and cell midpoints, a zeta0(x)'s values) are hashed
after gathering them on rank 0, duplicates (ghosts) removed and sorted by coordinates
(``nodal_digest``): 1, 2 or 3 ranks give the same digest, so a restart on another number of
ranks is accepted. The PETSc options the user gave to the package's solvers are an item too
(their defaults, which depend on the number of ranks, and diagnostics are not).
"""
from __future__ import annotations

import hashlib
import json

import numpy as np
from mpi4py import MPI

from damage_dolfinx.core.parameters import InputError
from damage_dolfinx.runtime import io

#: the fingerprint's format; a checkpoint of another format is refused (its items cannot all be
#: checked: format 3 had neither the model's code nor the tagged geometry)
VERSION = 4

#: how the items of the fingerprint are named in a refusal (in the order they are compared)
ITEMS = {"version": "the fingerprint's format (a checkpoint of another version of the "
                    "package: its run cannot be fully checked)",
         "model_code": "the model's code", "mesh": "the mesh",
         "mesh_nodes": "the mesh's nodes or cells",
         "tagged_geometry": "the mesh's tagged facets and cells (where each tag lies)",
         "traction": "the traction", "body_force": "the body force",
         "damage_law": "the damage law", "zeta0": "the initial damage zeta0",
         "boundaries": "the boundary parts", "irreversible": "irreversibility",
         "reading": "the reading", "builders": "the model's own data (builders)",
         "options": "the PETSc options given"}
#: items hashed from UFL (compared only between fingerprints of the same VERSION)
UFL_ITEMS = ("traction", "body_force", "damage_law")
#: PETSc options that change no result (diagnostics), left out of the fingerprint
_DIAGNOSTIC = ("monitor", "view", "converged_reason", "log", "test")


def fingerprint(ex, data) -> dict:
    """The fingerprint of the run of ``ex`` on ``data`` (the problem on its mesh,
    Problem.problem_data): the mesh
    (cells, vertices, bounding box, facet tags by count; a digest of its nodes and cells), the
    loads and the damage law by the canonical hash of the UFL they build on this mesh (their
    literals and constants' values included: a traction 100 times larger changes it), the
    initial damage, the boundary parts, irreversibility, the reading, the model's own data
    (builders) and the PETSc options given. Collective on the mesh's ranks."""
    from damage_dolfinx.problem.meshes import tag_counts
    msh = data.geometry.mesh
    comm = msh.comm
    tdim, gdim = msh.topology.dim, msh.geometry.dim
    # the user's functions first, on each rank with no collective call in between; one exchange
    # then decides for every rank (one that raises on one rank only is refused on all alike)
    error, user = None, {}
    try:
        user = _user_items(data, msh, gdim)
    except Exception as exc:  # noqa: BLE001 - a user function: named, one line
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
        error = f"{type(exc).__name__}: {first}"
    errors = [(rank, e) for rank, e in enumerate(comm.allgather(error)) if e is not None]
    if errors:
        rank, text = errors[0]
        where = f" (rank {rank})" if len(errors) < comm.size else ""
        raise InputError(f"a load, the damage law or zeta0(x) raised while the run's "
                         f"fingerprint was taken: {text}{where}")
    x_local = msh.geometry.x[:, :gdim]
    lo = np.array(x_local.min(axis=0) if len(x_local) else np.full(gdim, np.inf), dtype=float)
    hi = np.array(x_local.max(axis=0) if len(x_local) else np.full(gdim, -np.inf), dtype=float)
    comm.Allreduce(MPI.IN_PLACE, lo, op=MPI.MIN)
    comm.Allreduce(MPI.IN_PLACE, hi, op=MPI.MAX)
    out = {"version": VERSION,
           "mesh": f"{msh.topology.index_map(tdim).size_global} cells, "
                   f"{msh.topology.index_map(0).size_global} vertices, box "
                   f"{np.round(lo, 9).tolist()}-{np.round(hi, 9).tolist()}, tags "
                   f"{sorted(tag_counts(data.geometry).items())}",
           "mesh_nodes": mesh_digest(msh),
           "tagged_geometry": tagged_digest(data.geometry),
           "model_code": model_code(ex)}
    out.update({key: user[key] for key in ("traction", "body_force", "damage_law")})
    if "zeta0_values" in user:  # its values at the nodes, in an order no partition changes
        out["zeta0"] = "function of x, nodal digest " + nodal_digest(
            comm, msh.geometry.x[:, :gdim], user["zeta0_values"])
    else:
        out["zeta0"] = user["zeta0"]
    out["boundaries"] = repr(sorted((str(k), _tags(v))
                                    for k, v in (ex.boundaries or {}).items()))
    out["irreversible"] = bool(data.irreversible)
    out["reading"] = getattr(ex, "reading", None)
    out["builders"] = repr(sorted((str(k), repr(v) if not callable(v) else "function")
                                  for k, v in (data.builders or {}).items()))
    out["options"] = given_options()
    return json.loads(io.strict_json(out))


def _user_items(data, msh, gdim) -> dict:
    """The fingerprint's items that run the user's functions (the loads and the damage law by
    the hash of the UFL they build, zeta0(x) at this rank's nodes): local, no collective call."""
    import ufl
    from dolfinx import fem
    x = ufl.SpatialCoordinate(msh)
    t = fem.Constant(msh, 0.0)
    items = {}
    for name in ("traction", "body_force"):
        fn = getattr(data, name)
        items[name] = None if fn is None else ufl_hash(fn(x, t))
    law = data.damage_law or _thesis_law(data.params)
    e, z = ufl.sym(ufl.outer(x, x)), x[0] * 0 + t + 1.0
    items["damage_law"] = f"{getattr(law, 'name', '?')} {ufl_hash(law(e, z, data.params))}"
    z0 = data.zeta0
    if callable(z0):
        pts = np.ascontiguousarray(msh.geometry.x.T)
        items["zeta0_values"] = np.asarray(z0(pts[:gdim] if gdim < 3 else pts),
                                           dtype=float).reshape(-1)
    else:
        items["zeta0"] = float(z0)
    return items


def first_difference(saved, now):
    """(item, saved value, this value) of the first item of ITEMS that differs between two
    fingerprints, or None. A fingerprint of another VERSION is compared on the items that do
    not come from UFL."""
    if not isinstance(saved, dict) or not isinstance(now, dict):
        return None
    if saved.get("version", 1) != now.get("version", 1):  # not every item can be checked
        return "version", saved.get("version", 1), now.get("version", 1)
    same_version = True
    for key in ITEMS:
        if key in UFL_ITEMS and not same_version:
            continue
        if key == "zeta0" and not same_version and isinstance(saved.get(key), str):
            continue  # a function's earlier digest (its range)
        if key in saved and saved.get(key) != now.get(key):
            return key, saved.get(key), now.get(key)
    return None


def verify_fingerprint(ex, stepper, meta, out) -> dict:
    """The run's fingerprint; on a resume (``meta``: the checkpoint's metadata) InputError with
    one line naming the first item that differs from the checkpoint's."""
    fp = fingerprint(ex, stepper.data)
    differ = first_difference((meta or {}).get("fingerprint"), fp)
    if differ:
        key, saved, now = differ
        raise InputError(f"cannot restart: {ITEMS[key]} changed since the run in "
                         f"{str(out)!r} (checkpoint: {saved!r}, this run: {now!r}); choose "
                         "another --out to run it")
    return fp


def sweep_fingerprint(ex, out, n, k, T, values, comm) -> dict:
    """The fingerprint shared by every point of a sweep (built at one point: the parameters are
    compared as the grid); InputError naming the first item that changed when ``out`` holds
    a sweep of an earlier fingerprint (its finished points would be kept as this sweep's)."""
    from pathlib import Path
    fp = fingerprint(ex, ex.problem_data(comm, n=n, k=k, T=T, overrides=dict(values)))
    saved = None
    if comm.rank == 0:
        try:
            saved = json.loads((Path(out) / "points.json").read_text()).get("fingerprint")
        except (OSError, ValueError, AttributeError):
            saved = None
    differ = first_difference(comm.bcast(saved, root=0), fp)
    if differ:
        key, was, now = differ
        raise InputError(f"cannot run the sweep into {str(out)!r}: {ITEMS[key]} changed since "
                         f"its points were run (sweep: {was!r}, this sweep: {now!r}); choose "
                         "another out folder")
    return fp


# ---------------------------------------------------------------------------- nodal digests
def nodal_digest(comm, coords, values=None) -> str:
    """A hash of points (and values at them) that no partition changes: every rank's rows
    (ghost copies included) gathered on rank 0, rounded to 12 digits, duplicates removed,
    sorted by coordinates. Collective; the same text on every rank."""
    def table(a, n):  # n rows (a rank may hold none: NumPy cannot reshape 0 values to (0, -1))
        a = np.asarray(a, dtype=float)
        return a.reshape(n, -1) if a.size else np.zeros((n, 0))
    n = len(coords)
    rows = table(coords, n)
    if values is not None and n:
        rows = np.column_stack([rows, table(values, n)])
    gathered = comm.gather(np.round(rows, 12) + 0.0, root=0)  # + 0.0: no negative zero
    digest = None
    if comm.rank == 0:
        held = [g for g in gathered if g.shape[0]]  # the ranks that hold rows
        every = np.unique(np.concatenate(held), axis=0) if held else np.zeros((0, 0))
        digest = hashlib.sha1(np.ascontiguousarray(every).tobytes()).hexdigest()[:16]
    return comm.bcast(digest, root=0)


def tagged_digest(geometry) -> str:
    """Where each tag lies: the midpoints of the tagged facets with their tag, and of the tagged
    cells with theirs, by nodal_digest (partition-independent): two boundary tags swapped,
    with the same counts, are another mesh."""
    from damage_dolfinx import compat
    msh = geometry.mesh
    gdim, tdim = msh.geometry.dim, msh.topology.dim
    parts = []
    for tags, dim in ((geometry.facet_tags, tdim - 1), (getattr(geometry, "cell_tags", None),
                                                        tdim)):
        if tags is None:
            parts.append("none")
            continue
        indices = np.asarray(tags.indices, dtype=np.int32)
        if dim == tdim:
            mids = compat.cell_midpoints(msh)[indices, :gdim] if len(indices) else \
                np.zeros((0, gdim))
        else:
            msh.topology.create_connectivity(dim, 0)
            import dolfinx
            mids = dolfinx.mesh.compute_midpoints(msh, dim, indices)[:, :gdim] \
                if len(indices) else np.zeros((0, gdim))
        parts.append(nodal_digest(msh.comm, mids, np.asarray(tags.values, dtype=float)))
    return " ".join(parts)


def model_code(ex) -> str:
    """A digest of the model's own code: the source of its class and of every class of its MRO
    outside this package (the package's models are its version), else their functions'
    bytecode and constants (a class made by exec). An edit of the model changes it."""
    import inspect
    from damage_dolfinx.models.registry import model
    try:
        cls = model(ex.model)
    except Exception:  # noqa: BLE001 - no model class: nothing of the user's to hash
        return "none"
    h = hashlib.sha1()
    for klass in cls.__mro__:
        module = getattr(klass, "__module__", "") or ""
        if module.startswith("damage_dolfinx") or module == "builtins":
            continue
        try:
            h.update(inspect.getsource(klass).encode())
        except (OSError, TypeError):
            for name in sorted(vars(klass)):
                h.update(name.encode() + _code_bytes(vars(klass)[name]))
    return h.hexdigest()[:16]


def _code_bytes(obj) -> bytes:
    """The bytecode and constants of a function (a classmethod's, a property's), recursively;
    a plain value by its repr."""
    for attr in ("__func__", "fget"):
        if getattr(obj, attr, None) is not None:
            obj = getattr(obj, attr)
    code = getattr(obj, "__code__", None)
    if code is None:
        return repr(obj).encode() if isinstance(obj, (int, float, str, tuple, bool)) else b""

    def walk(c):
        out = c.co_code + repr(c.co_names).encode()
        for const in c.co_consts:
            out += walk(const) if hasattr(const, "co_code") else repr(const).encode()
        return out
    return walk(code)


def mesh_digest(msh) -> str:
    """The mesh's node coordinates and cell midpoints (its triangulation), by nodal_digest: a
    file of the same name with a node moved or a diagonal flipped is another mesh."""
    from damage_dolfinx import compat
    gdim = msh.geometry.dim
    return (nodal_digest(msh.comm, msh.geometry.x[:, :gdim]) + " "
            + nodal_digest(msh.comm, compat.cell_midpoints(msh)[:, :gdim]))


def given_options() -> list:
    """The PETSc options of the package's solvers that the user set (the command line's
    -prefix_option value, or the database directly), without the solvers' own defaults (they
    depend on the number of ranks) and without diagnostics: sorted [name, value] pairs."""
    import sys
    if "petsc4py.PETSc" not in sys.modules:
        return []
    from petsc4py import PETSc
    from damage_dolfinx.problem.petsc_options import PETSC_PREFIXES
    from damage_dolfinx.numerics import solvers
    given = []
    for name, value in PETSc.Options().getAll().items():
        if not name.startswith(PETSC_PREFIXES) or any(d in name for d in _DIAGNOSTIC):
            continue
        if name in solvers._CODE_DEFAULTS and \
                str(solvers._CODE_DEFAULTS[name]).lower() == str(value).lower():
            continue
        given.append([name, str(value)])
    return sorted(given)


# ---------------------------------------------------------------------------- canonical UFL
def ufl_hash(expr) -> str:
    """A hash of the UFL expression ``expr`` that is the same in every process running the same
    code (see the module's docstring); a non-UFL value (a number) by its text."""
    from ufl.core.expr import Expr
    if not isinstance(expr, Expr):
        return repr(expr)
    text = _canonical(expr) + "|" + _values_of(expr)
    return hashlib.sha1(text.encode()).hexdigest()[:16]


def _canonical(expr) -> str:
    from ufl.classes import (Coefficient, Constant, FixedIndex, GeometricQuantity, Index,
                             Label, MultiIndex, Product, Sum, Zero)
    from ufl.corealg.traversal import unique_pre_traversal
    nodes = list(unique_pre_traversal(expr))
    ranks = {}
    for kind in (Constant, Coefficient, Label):
        found = sorted({n for n in nodes if isinstance(n, kind)}, key=_count)
        ranks.update((n, i) for i, n in enumerate(found))
    indices = sorted({i for n in nodes if isinstance(n, MultiIndex) for i in n.indices()
                      if isinstance(i, Index)}, key=_count)
    index_rank = {i: r for r, i in enumerate(indices)}
    memo = {}

    def walk(node) -> str:
        key = id(node)
        if key in memo:
            return memo[key][1]
        if isinstance(node, MultiIndex):
            text = "MI(" + ",".join(f"i{index_rank[i]}" if isinstance(i, Index) else
                                    f"f{int(i)}" if isinstance(i, FixedIndex) else repr(i)
                                    for i in node.indices()) + ")"
        elif isinstance(node, (Constant, Coefficient)):
            element = node.ufl_element() if isinstance(node, Coefficient) else None
            text = (f"{type(node).__name__}{node.ufl_shape}#{ranks[node]}"
                    + (f"[{element}]" if element is not None else ""))
        elif isinstance(node, Label):
            text = f"L{ranks[node]}"
        elif isinstance(node, Zero):
            text = f"Zero{node.ufl_shape}/{len(node.ufl_free_indices)}"
        elif isinstance(node, GeometricQuantity):
            text = type(node).__name__
        elif node._ufl_is_terminal_:
            text = repr(node)  # numbers, identities: no creation count in their text
        else:
            parts = [walk(op) for op in node.ufl_operands]
            if isinstance(node, (Sum, Product)):
                parts.sort()
            text = f"{type(node).__name__}({','.join(parts)})"
            if len(text) > 64:  # keep the texts short: a deep tree is hashed level by level
                text = type(node).__name__ + ":" + hashlib.sha1(text.encode()).hexdigest()
        memo[key] = (node, text)
        return text

    return walk(expr)


def _count(obj) -> int:
    for attr in ("count", "_count"):
        value = getattr(obj, attr, None)
        if callable(value):
            value = value()
        if isinstance(value, int):
            return value
    return 0


def _values_of(expr) -> str:
    """The values a symbolic hash leaves out, partition-independent, in the canonical order of
    the terminals: those of constants (a load ``c * t`` with ``c`` a fem.Constant the user
    changes; the time is a constant of value 0 here) and, for each function, its global size
    and the sum of squares of its values (9 digits)."""
    from ufl.classes import Coefficient, Constant
    from ufl.corealg.traversal import unique_pre_traversal
    nodes = list(unique_pre_traversal(expr))
    parts = []
    for c in sorted({n for n in nodes if isinstance(n, Constant)}, key=_count):
        value = getattr(c, "value", None)
        parts.append("c" + (np.array2string(np.round(np.asarray(value, dtype=float), 12))
                            if value is not None else "?"))
    for f in sorted({n for n in nodes if isinstance(n, Coefficient)}, key=_count):
        x = getattr(f, "x", None)
        if x is None:
            parts.append("f?")
            continue
        V = f.function_space
        owned = x.array[:V.dofmap.index_map.size_local * V.dofmap.index_map_bs]
        comm = V.mesh.comm
        size = comm.allreduce(len(owned), op=MPI.SUM)
        squares = comm.allreduce(float(np.sum(np.abs(owned) ** 2)), op=MPI.SUM)
        parts.append(f"f{size}:{squares:.9g}")
    return ";".join(parts)


def _thesis_law(params):
    from damage_dolfinx.models.laws import thesis_law
    return thesis_law(params.variant)


def _tags(v):
    """A boundary entry as the fingerprint holds it: a tag, a gmsh physical name, or a sorted
    list of them (numbers as numbers, names as names)."""
    if isinstance(v, (int, np.integer, str)):
        return v if isinstance(v, str) else int(v)
    if len(v) == 1:  # [2] names the same part as 2
        return _tags(list(v)[0])
    if all(not isinstance(x, str) for x in v):
        return sorted(map(int, v))
    return sorted(map(str, v))
