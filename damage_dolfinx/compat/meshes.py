"""Meshes: creation, entities and tags, cell and facet geometry, gmsh and XDMF files.

Version-specific calls only (damage_dolfinx.compat); imported from there."""
from __future__ import annotations

import inspect

import numpy as np
import ufl
import dolfinx
from dolfinx import mesh as dmesh


def create_rectangle(comm, p0, p1, n, diagonal: str = "right"):
    return dmesh.create_rectangle(comm, [np.asarray(p0, float), np.asarray(p1, float)], list(n),
                                  dmesh.CellType.triangle,
                                  diagonal=getattr(dmesh.DiagonalType, diagonal))


def create_box(comm, p0, p1, n):
    """Structured box (p0, p1) with n = (nx, ny, nz) hexahedra, each cut into 6 tetrahedra."""
    return dmesh.create_box(comm, [np.asarray(p0, float), np.asarray(p1, float)], list(n),
                            dmesh.CellType.tetrahedron)


def create_simplex_mesh(comm, cells, x):
    """P1 triangle (``cells`` with 3 columns, ``x`` with 2) or tetrahedron (4 columns, 3) mesh
    from this rank's cells (int64 global vertex numbers) and this rank's block of vertex
    coordinates ``x`` (rank r's rows are the vertices offset_r, offset_r + 1, ..., offsets in
    rank order), partitioned and ghosted (shared facets) like ``create_rectangle`` and
    ``create_box``."""
    mode = dmesh.GhostMode.shared_facet
    cells = np.asarray(cells, dtype=np.int64)
    nv = cells.shape[1]
    cell, gdim = {3: ("triangle", 2), 4: ("tetrahedron", 3)}[nv]
    cells = cells.reshape(-1, nv)
    x = np.ascontiguousarray(np.asarray(x, dtype=np.float64).reshape(-1, gdim))
    if "domain" in inspect.signature(dmesh.create_mesh).parameters:  # 0.5-0.6
        domain = ufl.Mesh(ufl.VectorElement("Lagrange", getattr(ufl, cell), 1))
        return dmesh.create_mesh(comm, cells, x, domain, ghost_mode=mode)
    import basix.ufl
    domain = ufl.Mesh(basix.ufl.element("Lagrange", cell, 1, shape=(gdim,)))
    try:
        partitioner = dmesh.create_cell_partitioner(mode, 2)  # 0.10+: max facet-cell links
    except TypeError:
        partitioner = dmesh.create_cell_partitioner(mode)
    return dmesh.create_mesh(comm, cells=cells, x=x, e=domain, partitioner=partitioner)


def create_tet_mesh(comm, cells, x):
    """P1 tetrahedral mesh (:func:`create_simplex_mesh` with 4 vertices a cell)."""
    return create_simplex_mesh(comm, np.asarray(cells, dtype=np.int64).reshape(-1, 4), x)


def create_submesh(msh, dim, entities):
    """Submesh of the given entities; returns the mesh only (maps differ between versions)."""
    out = dmesh.create_submesh(msh, dim, entities)
    return out[0]


def locate_entities_boundary(msh, dim, marker):
    msh.topology.create_connectivity(dim, msh.topology.dim)
    return dmesh.locate_entities_boundary(msh, dim, marker)


def locate_entities(msh, dim, marker):
    return dmesh.locate_entities(msh, dim, marker)


def geometry_dofmap(msh):
    """(n_local_cells, nodes per cell) geometry node indices of all local cells (owned, then
    ghosts) into ``msh.geometry.x``: 0.5's AdjacencyList, 0.6-0.9's array, 0.10+'s first of
    the per-cell-type ``dofmaps``."""
    dms = getattr(msh.geometry, "dofmaps", None)
    dm = (dms(0) if callable(dms) else dms[0]) if dms is not None else msh.geometry.dofmap
    return dm.array.reshape(-1, dm.links(0).size) if hasattr(dm, "array") else np.asarray(dm)


def cell_diameters(msh, cells):
    """Largest vertex distance of the given local cells (NumPy; 0.5.2's ``cpp.mesh.h`` refuses
    the Python Mesh)."""
    xs = msh.geometry.x[geometry_dofmap(msh)[np.asarray(cells, dtype=np.int64)]]
    d = xs[:, :, None, :] - xs[:, None, :, :]
    return np.sqrt((d ** 2).sum(axis=-1)).max(axis=(1, 2))


def meshtags(msh, dim, entities, values):
    order = np.argsort(entities)
    return dmesh.meshtags(msh, dim, np.asarray(entities, np.int32)[order],
                          np.asarray(values, np.int32)[order])


def cell_midpoints(msh):
    """Midpoints of all local cells (owned and ghost), shape (num_cells, 3)."""
    tdim = msh.topology.dim
    imap = msh.topology.index_map(tdim)
    cells = np.arange(imap.size_local + imap.num_ghosts, dtype=np.int32)
    return dmesh.compute_midpoints(msh, tdim, cells)


def num_owned_cells(msh) -> int:
    return msh.topology.index_map(msh.topology.dim).size_local


def cell_vertex_coords(msh):
    """(n_owned_cells, nverts, 2) coordinates of the owned cells' geometry nodes (P1 meshes)."""
    return msh.geometry.x[geometry_dofmap(msh)[:num_owned_cells(msh)]][:, :, :2]


def cell_dofs(V):
    """(n_owned_cells, ndofs_per_cell) local dof indices (block index for vector spaces)."""
    nc = num_owned_cells(V.mesh)
    dl = V.dofmap.list
    arr = dl.array.reshape(-1, dl.links(0).size) if hasattr(dl, "array") else dl
    return arr[:nc]


def model_to_mesh(model, comm, rank=0, gdim=2):
    """gmsh model -> (mesh, cell_tags, facet_tags), the model living on ``rank``."""
    try:
        from dolfinx.io import gmshio
        out = gmshio.model_to_mesh(model, comm, rank, gdim=gdim)
    except ImportError:  # 0.10
        from dolfinx.io import gmsh as gmshio
        out = gmshio.model_to_mesh(model, comm, rank, gdim=gdim)
    if hasattr(out, "mesh"):
        return out.mesh, out.cell_tags, out.facet_tags
    return out


def xdmf_file(comm, path, mode):
    from dolfinx.io import XDMFFile
    return XDMFFile(comm, str(path), mode)


def read_msh(comm, path, rank=0, gdim=None, check=None):
    """.msh file -> (mesh, cell_tags, facet_tags) on every version: gmsh reads the file on
    ``rank`` into a model of its own, which ``model_to_mesh`` distributes (DOLFINx 0.5.2's
    ``gmshio.read_from_msh`` returns an undefined name, so it is not used anywhere). ``gdim``:
    the geometric dimension (None: the model's dimension). ``check(gmsh) -> str | None`` looks at
    the model on ``rank`` before anything is distributed; a message (or gmsh's own error while
    reading) raises ValueError on every rank."""
    from damage_dolfinx.compat.gmsh import gmsh_session
    gmsh = gmsh_session()
    dim, error = None, None
    if comm.rank == rank:
        gmsh.model.add("damage_dolfinx_read")
        try:
            gmsh.merge(str(path))
            dim = gmsh.model.getDimension()
            error = check(gmsh) if check else None
        except Exception as exc:  # gmsh raises a bare Exception with its own message
            error = f"gmsh cannot read it ({str(exc).strip() or type(exc).__name__})"
    dim, error = comm.bcast((dim, error), root=rank)
    try:
        if error:
            raise ValueError(error)
        return model_to_mesh(gmsh.model, comm, rank, gdim=gdim or dim)
    finally:
        if comm.rank == rank:
            gmsh.model.remove()


def dofs_in_cells(V):
    """Local dof (block) indices used by some local cell (a parallel submesh may carry ghost
    vertices attached to no local cell; their dofs are never assembled)."""
    dl = V.dofmap.list
    return np.unique(dl.array if hasattr(dl, "array") else dl)


def facet_coords(msh, facets):
    """(len(facets), vertices per facet, gdim) coordinates of the given local facets' vertices
    (any dimension; ``facet_vertex_coords`` is the 2-D form of the thesis meshes)."""
    tdim, gdim = msh.topology.dim, msh.geometry.dim
    facets = np.asarray(facets, dtype=np.int32)
    if facets.size == 0:
        return np.zeros((0, tdim, gdim))
    msh.topology.create_connectivity(tdim - 1, tdim)
    if hasattr(dmesh, "entities_to_geometry"):  # 0.7+
        nodes = dmesh.entities_to_geometry(msh, tdim - 1, facets, False)
    else:
        cpp_mesh = getattr(msh, "_cpp_object", getattr(msh, "_mesh", msh))
        nodes = dolfinx.cpp.mesh.entities_to_geometry(cpp_mesh, tdim - 1, facets, False)
    return msh.geometry.x[nodes][:, :, :gdim]


def facet_vertex_coords(msh, facets):
    """(len(facets), 2, 2) coordinates of the end points of the given local facets."""
    facets = np.asarray(facets, dtype=np.int32)
    if facets.size == 0:
        return np.zeros((0, 2, 2))
    if hasattr(dmesh, "entities_to_geometry"):  # 0.7+
        nodes = dmesh.entities_to_geometry(msh, 1, facets, False)
    else:
        cpp_mesh = getattr(msh, "_cpp_object", getattr(msh, "_mesh", msh))
        nodes = dolfinx.cpp.mesh.entities_to_geometry(cpp_mesh, 1, facets, False)
    return msh.geometry.x[nodes][:, :, :2]


def geometry_input_indices(msh) -> np.ndarray:
    """For every local geometry node (owned, then ghosts) its index in the input data the mesh
    was created from (the generator's or the file's node order: independent of the number of
    ranks); the same property on 0.5 to 0.11."""
    return np.asarray(msh.geometry.input_global_indices, dtype=np.int64)


def num_owned_nodes(msh) -> int:
    """Geometry nodes owned by this rank (the first ones of ``msh.geometry.x``)."""
    imap = msh.geometry.index_map
    return int((imap() if callable(imap) else imap).size_local)


def dofmap_array(V) -> np.ndarray:
    """(n_local_cells, ndofs_per_cell) local (block) dof indices of all local cells, owned then
    ghosts (0.5's AdjacencyList, the array of later versions)."""
    dl = V.dofmap.list
    return np.asarray(dl.array.reshape(-1, dl.links(0).size) if hasattr(dl, "array") else dl)


def cell_type_name(msh) -> str:
    """The cell type's name: 'triangle', 'tetrahedron', 'quadrilateral', ..."""
    ct = msh.topology.cell_type
    return getattr(ct, "name", str(ct).rsplit(".", 1)[-1])
