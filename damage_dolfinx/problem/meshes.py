"""Meshes of your own: a gmsh ``.msh`` file, a gmsh model, or a DOLFINx mesh with facet tags.

Every model reads the parts of the boundary from *facet tags* (integers on the boundary facets):
in gmsh, *physical curves* (2-D) or *physical surfaces* (3-D); the cells must belong to a
physical surface (2-D) or volume (3-D). Which tag plays which role (clamped, loaded, in contact)
is said by :class:`~damage_dolfinx.Problem`'s ``boundaries``, by tag number or by the gmsh
physical name of the group (``boundaries={"clamped": "left", "tresca": ["bottom", 7]}``; a name
the mesh does not have is refused with the names it has). The thesis catalogue and
``damage-dolfinx run ID --mesh FILE`` use the fixed convention

    1 = Gamma_D (clamped),  2 = Gamma_N (traction),  3 = Gamma_C (contact).

A file that cannot be read, has the wrong dimension, has no tagged cells or boundary, or lacks a
tag that is needed is refused with one line (:class:`~damage_dolfinx.InputError`).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
from mpi4py import MPI

from damage_dolfinx.core.geometry import Geometry
from damage_dolfinx.core.tags import CONTACT_ROLES
from damage_dolfinx.core.parameters import InputError


def _check_model(dim):
    """check(gmsh) of compat.read_msh: cells and boundary tagged, the expected dimension."""
    def check(gmsh):
        d = gmsh.model.getDimension()
        if d < 2:
            return (f"it holds a {max(d, 0)}-D model, not a 2-D or 3-D mesh" if d >= 0 else
                    "it holds no mesh")
        if dim is not None and d != dim:
            return f"it holds a {d}-D mesh; this problem is {dim}-D"
        from damage_dolfinx.core.validation import cell_types_problem, claims_problem
        mixed = cell_types_problem(gmsh, d)
        if mixed:
            return mixed
        groups = gmsh.model.getPhysicalGroups()
        if not any(g[0] == d for g in groups):
            return (f"no physical {'surface' if d == 2 else 'volume'} holds the cells: tag them "
                    "(gmsh: Physical Surface/Volume)")
        if not any(g[0] == d - 1 for g in groups):
            return (f"no physical {'curve' if d == 2 else 'surface'} tags the boundary: tag the "
                    "clamped, loaded and contact parts (README: mesh files)")
        return claims_problem(gmsh, d)
    return check


def _facet_names(gmsh) -> dict:
    """{physical name: tag} of the physical groups one dimension below the model's (rank 0)."""
    d = gmsh.model.getDimension()
    names = {}
    for gd, tag in gmsh.model.getPhysicalGroups(d - 1):
        name = gmsh.model.getPhysicalName(gd, tag)
        if name:
            names[name] = int(tag)
    return names


def read_mesh(path, comm=MPI.COMM_WORLD, dim=None) -> Geometry:
    """A gmsh ``.msh`` file as a :class:`~damage_dolfinx.geometries.Geometry` (mesh and facet
    tags), read on rank 0 and distributed over ``comm``. ``dim``: the dimension the problem
    needs (None: the file's). Raises InputError with the file name and what is wrong."""
    from damage_dolfinx.core.validation import check_mesh_reading
    check_mesh_reading(path, dim, comm)
    path = Path(path)
    if path.suffix.lower() != ".msh":
        raise InputError(f"mesh file {str(path)!r}: expected a gmsh .msh file")
    if path.stat().st_size == 0:
        raise InputError(f"mesh file {str(path)!r} is empty")
    from damage_dolfinx import compat
    names = {}

    def check(gmsh):  # on rank 0, the file's model loaded: also its physical names
        error = _check_model(dim)(gmsh)
        if error is None:
            names.update(_facet_names(gmsh))
        return error
    try:
        msh, _, facet_tags = compat.read_msh(comm, path, check=check)
    except ValueError as exc:
        raise InputError(f"mesh file {str(path)!r}: {exc}") from None
    return _geometry(msh, facet_tags, f"gmsh file {path.name}", comm.bcast(names, root=0))


def from_gmsh(model=None, comm=MPI.COMM_WORLD, dim=None) -> Geometry:
    """The mesh of a gmsh model (default: the current ``gmsh.model``, meshed, on rank 0)."""
    from damage_dolfinx import compat
    from damage_dolfinx.compat.gmsh import import_gmsh_keeping_sigint
    import_gmsh_keeping_sigint()
    import gmsh
    from damage_dolfinx.core.validation import check_dim, communicator
    check_dim(dim)
    communicator("comm", comm)
    model = model or gmsh.model
    if not hasattr(model, "getDimension"):
        raise InputError(f"from_gmsh: model must be a gmsh model (gmsh.model), got "
                         f"{type(model).__name__}")
    error = _check_model(dim)(gmsh) if comm.rank == 0 else None
    error = comm.bcast(error, root=0)
    if error:
        raise InputError(f"gmsh model: {error}")
    d = comm.bcast(model.getDimension() if comm.rank == 0 else None, root=0)
    names = comm.bcast(_facet_names(gmsh) if comm.rank == 0 else None, root=0)
    msh, _, facet_tags = compat.model_to_mesh(model, comm, 0, gdim=d)
    return _geometry(msh, facet_tags, "gmsh model", names)


def as_geometry(mesh, comm=MPI.COMM_WORLD, dim=None) -> Geometry:
    """What :class:`~damage_dolfinx.Problem` accepts as its mesh, as a Geometry: a Geometry, a
    ``(mesh, facet_tags)`` pair, or a path to a ``.msh`` file."""
    if isinstance(mesh, Geometry):
        return mesh
    if isinstance(mesh, (str, Path)):
        return read_mesh(mesh, comm, dim)
    if isinstance(mesh, tuple) and len(mesh) == 2:
        return _geometry(*mesh, "user mesh")
    raise InputError("a mesh must be a Geometry, a (mesh, facet_tags) pair, a .msh path or a "
                     f"function (comm, n) -> one of these; got {type(mesh).__name__}")


def _geometry(msh, facet_tags, description, names=None) -> Geometry:
    tdim = msh.topology.dim
    num = msh.topology.index_map(tdim).size_local
    h = 0.0
    if num:
        from damage_dolfinx import compat
        h = float(np.max(compat.cell_diameters(msh, np.arange(num))))
    h = msh.comm.allreduce(h, op=MPI.MAX)
    return Geometry(msh, facet_tags, h=h, description=description, names=names or None)


def tag_counts(geometry: Geometry) -> dict:
    """{tag: number of facets} over all ranks."""
    values = geometry.facet_tags.values if geometry.facet_tags is not None else np.zeros(0, int)
    imap = geometry.mesh.topology.index_map(geometry.mesh.topology.dim - 1)
    owned = geometry.facet_tags.indices < imap.size_local if values.size else np.zeros(0, bool)
    local = {}
    for v in np.unique(values[owned]) if values.size else []:
        local[int(v)] = int(np.sum(values[owned] == v))
    out = {}
    for d in geometry.mesh.comm.allgather(local):
        for key, count in d.items():
            out[key] = out.get(key, 0) + count
    return out




def retag(geometry: Geometry, boundaries, required=None, model=None) -> Geometry:
    """The geometry with its facet tags renamed to the roles the models read (1 clamped,
    2 traction, 3 contact), from ``boundaries`` = {role: tag or tags}; None keeps the tags as
    they are. Every tag named (or ``required`` = {what: tag}) must be present and non-empty.
    ``model``: the model class, whose ``boundary_roles()`` are the roles allowed."""
    from damage_dolfinx import compat
    from damage_dolfinx.core.tags import GAMMA_C as CONTACT, GAMMA_D as CLAMPED, GAMMA_N as TRACTION
    counts = tag_counts(geometry)
    where = geometry.description or "the mesh"
    for what, tag in (required or {}).items():
        if not counts.get(tag):
            raise InputError(f"{where}: the {what} tag {tag} is missing or empty")
    if boundaries is None:
        return geometry
    internal = model.boundary_roles() if model else \
        {"clamped": CLAMPED, "traction": TRACTION, **{r: CONTACT for r in CONTACT_ROLES}}
    allowed = tuple(internal)
    mapping = {}
    for role, tags in boundaries.items():
        if role not in allowed:
            raise InputError(f"boundary role {role!r} is not one of model {model.id}'s: "
                             f"{', '.join(allowed)}")
        for tag in _tag_numbers(geometry, role, tags, where):
            if not counts.get(int(tag)):
                raise InputError(f"{where}: the {role} tag {int(tag)} is missing or empty "
                                 f"(tags present: {sorted(counts) or 'none'})")
            if int(tag) in mapping:
                raise InputError(f"facet tag {int(tag)} is given two roles")
            mapping[int(tag)] = internal[role]
    roles = {tag: role for role, tags in boundaries.items()
             for tag in _tag_numbers(geometry, role, tags, where)}
    inside = off_boundary(geometry, sorted(mapping))
    if inside:
        tag, count = next(iter(inside.items()))
        raise InputError(f"{where}: the {roles[tag]} tag {tag} lies inside the body ({count} "
                         f"of its {counts[tag]} facets are not on the boundary): a boundary "
                         "part must be on the boundary (an interior curve carries no load, "
                         "contact or support)")
    ft = geometry.facet_tags
    keep = np.isin(ft.values, list(mapping))
    values = np.array([mapping[int(v)] for v in ft.values[keep]], dtype=np.int32)
    tags = compat.meshtags(geometry.mesh, geometry.mesh.topology.dim - 1, ft.indices[keep], values)
    return Geometry(geometry.mesh, tags, geometry.h, geometry.grid, geometry.description,
                    geometry.names)


def off_boundary(geometry: Geometry, tags) -> dict:
    """{tag: number of its facets not on the boundary of the body} over all ranks, for the
    ``tags`` that have such facets (collective)."""
    import dolfinx
    msh, ft = geometry.mesh, geometry.facet_tags
    tdim = msh.topology.dim
    local = np.zeros(len(tags), dtype=np.int64)
    if ft is not None and len(tags):
        msh.topology.create_connectivity(tdim - 1, tdim)
        exterior = dolfinx.mesh.exterior_facet_indices(msh.topology)
        owned = ft.indices < msh.topology.index_map(tdim - 1).size_local
        outside = np.isin(ft.indices, exterior)
        for i, tag in enumerate(tags):
            local[i] = int(np.sum((ft.values == tag) & owned & ~outside))
    total = msh.comm.allreduce(local)
    return {int(tag): int(n) for tag, n in zip(tags, total) if n}


def _tag_numbers(geometry, role, tags, where) -> list:
    """The tag numbers of ``boundaries[role]``: a tag, a gmsh physical name, or a list of
    them; a name the mesh does not have is refused with the names it has."""
    items = [tags] if isinstance(tags, (int, np.integer, str)) else list(tags)
    names = geometry.names or {}
    numbers = []
    for item in items:
        if isinstance(item, str):
            if item not in names:
                present = ", ".join(repr(n) for n in sorted(names)) or "none (the mesh has no " \
                    "physical names: give tag numbers)"
                raise InputError(f"{where}: the {role} boundary {item!r} is not a physical "
                                 f"name of the mesh; names present: {present}")
            item = names[item]
        if isinstance(item, bool) or not isinstance(item, (int, np.integer)):
            raise InputError(f"boundaries[{role!r}]: a tag number, a gmsh physical name or a list "
                             f"of them, got {item!r}")
        numbers.append(int(item))
    return numbers
