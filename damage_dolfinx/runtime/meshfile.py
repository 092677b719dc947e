"""The checks of a gmsh mesh file before it is used (:func:`check_mesh_file`): readable, of the
example's dimension, one cell type, the boundary tags the example needs; read by gmsh's own
reader, outside any DOLFINx call."""
from __future__ import annotations

from pathlib import Path

from mpi4py import MPI

from damage_dolfinx.core.parameters import InputError


def check_mesh_file(path, dim, required_tags=(), comm=MPI.COMM_WORLD):
    """A gmsh .msh file is readable, holds cells of topological dimension ``dim`` and facet
    (dimension dim - 1) physical tags including every one of ``required_tags``; raises
    InputError with one line naming the file and what is wrong (rank 0 reads, all ranks
    raise). Read by gmsh's own reader, outside any DOLFINx call. ``required_tags`` may be a
    callable returning them (evaluated on rank 0 only, after the file itself passed)."""
    error = _mesh_problem(Path(path), dim, required_tags) if comm.rank == 0 else None
    error = comm.bcast(error, root=0)
    if error:
        raise InputError(f"mesh file {str(path)!r}: {error}")


def _mesh_problem(path, dim, required):
    from damage_dolfinx.core.validation import cell_types_problem, mesh_path_problem
    problem = mesh_path_problem(path)
    if problem:
        return problem
    try:
        size = path.stat().st_size
        with open(path, "rb") as f:
            head = f.read(64)
    except OSError as exc:
        return f"cannot be read ({exc.strerror or exc})"
    if size == 0:
        return "is empty"
    if not head.lstrip().startswith(b"$MeshFormat"):
        return "is not a gmsh .msh file (no $MeshFormat header)"
    gmsh = _gmsh()
    gmsh.model.add("check_mesh_file")
    try:
        try:
            gmsh.merge(str(path))
        except Exception as exc:  # noqa: BLE001 - gmsh raises a bare Exception
            return f"gmsh cannot read it ({str(exc).splitlines()[0] if str(exc) else 'error'})"
        got = gmsh.model.getDimension()
        if got != dim or len(gmsh.model.mesh.getElementTypes(dim)) == 0:
            return f"holds a {got}-D mesh, this example needs a {dim}-D one"
        from damage_dolfinx.core.validation import claims_problem
        mixed = cell_types_problem(gmsh, dim)
        if mixed:
            return mixed
        if gmsh.model.getPhysicalGroups(dim):
            mixed = claims_problem(gmsh, dim)
            if mixed:
                return mixed
        if not gmsh.model.getPhysicalGroups(dim):
            return f"has no physical group of dimension {dim} (the cells)"
        tags = {t for _, t in gmsh.model.getPhysicalGroups(dim - 1)}
    finally:
        gmsh.model.remove()
    required = required() if callable(required) else required
    missing = sorted(set(required) - tags)
    if missing:
        return (f"lacks the boundary tags {missing} this example needs (has "
                f"{sorted(tags) or 'none'}; 1 = Gamma_D, 2 = Gamma_N, 3 = Gamma_C)")
    return None


def _gmsh():
    """The gmsh module, initialised (gmsh 4.8 has no isInitialized; DOLFINx's reader finalises
    gmsh after reading a file, behind geometries.gmsh_session's back)."""
    import os
    from damage_dolfinx.compat.gmsh import gmsh_session
    gmsh = gmsh_session()
    saved = os.dup(2)  # gmsh prints "not initialized" itself before raising
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, 2)
        os.close(devnull)
        try:
            gmsh.model.getCurrent()
        except Exception:  # noqa: BLE001 - finalised: start it again
            gmsh.initialize()
            gmsh.option.setNumber("General.Terminal", 0)
    finally:
        os.dup2(saved, 2)
        os.close(saved)
    return gmsh
