"""Every DOLFINx-version-specific call of the package, in one place.

The package targets DOLFINx 0.5.2 (Debian 12). Differences with newer releases are handled by
feature probes (``hasattr``) rather than version strings, so a port to 0.9/0.10 touches this
file only. Nothing else in the package may call an API listed here directly.
"""
from __future__ import annotations

import inspect
import logging

import numpy as np
import ufl
import dolfinx
import dolfinx.fem.petsc  # noqa: F401  (0.7+ no longer imports it implicitly)
from dolfinx import fem, mesh as dmesh
from petsc4py import PETSc

import ffcx  # noqa: E402,F401  (installs a root log handler at import)


class _WarningsOnly(logging.Filter):
    def filter(self, record):
        return record.levelno >= logging.WARNING


# The JIT's C compilation (setuptools) logs every build at INFO on the root logger, and
# setuptools resets the root level while doing so: filter at the handlers instead.
for _handler in logging.getLogger().handlers:
    _handler.addFilter(_WarningsOnly())

DOLFINX_VERSION = dolfinx.__version__
#: "no limit" for a PETSc tolerance (switches a test off): -1 up to PETSc 3.21; from 3.22 on -1 is
#: PETSC_DETERMINE (the default value, e.g. divtol 1e4) and PETSC_UNLIMITED = -3 switches it off
PETSC_UNLIMITED = int(getattr(PETSc, "UNLIMITED", -1))
ScalarType = getattr(dolfinx, "default_scalar_type", PETSc.ScalarType)


# ---------------------------------------------------------------------------- function spaces
def function_space(msh, family: str, degree: int, shape: tuple = ()):
    """Lagrange/DG space with value shape () (scalar), (gdim,) (vector) or (gdim, gdim)."""
    if hasattr(fem, "functionspace"):  # 0.7+
        return fem.functionspace(msh, (family, degree, shape) if shape else (family, degree))
    cell = msh.ufl_cell()
    if shape == ():
        return fem.FunctionSpace(msh, (family, degree))
    if len(shape) == 1:
        return fem.FunctionSpace(msh, ufl.VectorElement(family, cell, degree, dim=shape[0]))
    return fem.FunctionSpace(msh, ufl.TensorElement(family, cell, degree, shape=shape))


def element_degree(V) -> int:
    """Polynomial degree of V's element (a method of the legacy UFL element, a property of
    basix.ufl elements from 0.7 on)."""
    d = V.ufl_element().degree
    return int(d() if callable(d) else d)


def is_discontinuous(V) -> bool:
    """True for DG spaces (legacy UFL: family 'Discontinuous Lagrange'; basix.ufl: a flag)."""
    e = V.ufl_element()
    flag = getattr(e, "discontinuous", None)
    if isinstance(flag, bool):
        return flag
    family = e.family() if callable(getattr(e, "family", None)) else str(getattr(e, "family_name", ""))
    return "Discontinuous" in family or family in ("DG", "DP")


def scalar_p1(msh):
    return function_space(msh, "Lagrange", 1)


def vector_p1(msh):
    """P1 vectors with one component per space dimension (2 on every thesis mesh, 3 in 3-D)."""
    return function_space(msh, "Lagrange", 1, (msh.topology.dim,))


def scalar_dg0(msh):
    return function_space(msh, "DG", 0)


def tensor_dg0(msh):
    d = msh.topology.dim
    return function_space(msh, "DG", 0, (d, d))


def facet_vertex_quadrature() -> dict:
    """Integration metadata of the vertex rule on the triangular facets of a tetrahedral mesh
    (nodal quadrature of a 3-D boundary integral). FFCx 0.9+ applies its "vertex"
    scheme to the facet; FFCx 0.5 applies it to the cell (tetrahedron points on a facet) and
    Basix has no GLL rule on triangles, so there the rule is given explicitly: weight 1/6 (a
    third of the reference triangle's area) at each vertex."""
    major, minor = (int(part) for part in ffcx.__version__.split(".")[:2])
    if (major, minor) >= (0, 9):
        return {"quadrature_rule": "vertex", "quadrature_degree": 1}
    return {"quadrature_rule": "custom", "quadrature_degree": 1,
            "quadrature_points": ((0.0, 0.0), (1.0, 0.0), (0.0, 1.0)),
            "quadrature_weights": (1.0 / 6.0,) * 3}


# ---------------------------------------------------------------------------- vectors
def petsc_vec(u: fem.Function) -> PETSc.Vec:
    """The PETSc vector that wraps a Function's dof array (ghosted)."""
    return u.x.petsc_vec if hasattr(u.x, "petsc_vec") else u.vector


def create_vector(L_form) -> PETSc.Vec:
    try:
        return fem.petsc.create_vector(L_form)
    except TypeError:  # 0.10: takes function spaces
        return fem.petsc.create_vector(fem.extract_function_spaces(L_form))


def create_matrix(a_form, mat_type=None) -> PETSc.Mat:
    """The matrix of a bilinear form; ``mat_type`` e.g. "baij" (the second positional argument
    is mat_type up to 0.9 and kind from 0.10 on: the same strings)."""
    if mat_type is None:
        return fem.petsc.create_matrix(a_form)
    return fem.petsc.create_matrix(a_form, mat_type)


def assemble_vector(b, L_form):
    fem.petsc.assemble_vector(b, L_form)


def assemble_vector_array(b: np.ndarray, L_form):
    """Add the assembled L_form into the array ``b`` (local entries, ghosts included, no ghost
    update): the ndarray path of fem.assemble_vector in 0.5-0.11, without the PETSc local
    form of assemble_vector (a few microseconds a call on small meshes)."""
    fem.assemble_vector(b, L_form)


def assemble_matrix(A, a_form, bcs):
    fem.petsc.assemble_matrix(A, a_form, bcs=bcs)


#: keyword of the lifting / Dirichlet scale factor: 'scale' up to 0.8, 'alpha' from 0.9 on
#: (probed once here, not by catching TypeError on every call of these per-step functions)
_SCALE_KEY = "alpha" if "alpha" in inspect.signature(fem.petsc.set_bc).parameters else "scale"


def apply_lifting(b, a_form, bcs, x0=None, scale=1.0):
    """b -= scale * A (g - x0) on the columns of Dirichlet dofs ('scale' <= 0.8, 'alpha' >= 0.9)."""
    fem.petsc.apply_lifting(b, [a_form], [bcs], [] if x0 is None else [x0],
                            **{_SCALE_KEY: scale})


def set_bc(b, bcs, x0=None, scale=1.0):
    fem.petsc.set_bc(b, bcs, x0, **{_SCALE_KEY: scale})


_FORM_OPTIONS_KEY = "jit_options" if "jit_options" in fem.form.__code__.co_varnames else "jit_params"
_FORM_TYPES = tuple(t for t in (getattr(fem, "FormMetaClass", None), getattr(fem, "Form", None))
                    if isinstance(t, type))


def form(ufl_form, jit_options=None):
    """Compiled form; JIT options are 'jit_params' up to 0.5, 'jit_options' from 0.6 on."""
    if not jit_options:
        return fem.form(ufl_form)
    return fem.form(ufl_form, **{_FORM_OPTIONS_KEY: jit_options})


def assemble_scalar(ufl_or_form, comm) -> float:
    """Globally summed integral of a scalar form (compiled or UFL)."""
    f = ufl_or_form if isinstance(ufl_or_form, _FORM_TYPES) else fem.form(ufl_or_form)
    return comm.allreduce(fem.assemble_scalar(f), op=_mpi_sum())


def _mpi_sum():
    from mpi4py import MPI
    return MPI.SUM


# ---------------------------------------------------------------------------- interpolation
def interpolation_points(V):
    pts = V.element.interpolation_points
    return pts() if callable(pts) else pts


def expression(expr, V):
    """A compiled fem.Expression of ``expr`` at the interpolation points of V."""
    return fem.Expression(expr, interpolation_points(V))


def eval_expression(expr, msh, cells):
    """Values of a compiled fem.Expression at its points in the given local cells
    (``eval(cells)`` up to 0.8, ``eval(mesh, cells)`` from 0.9 on)."""
    cells = np.asarray(cells, dtype=np.int32)
    try:
        return expr.eval(msh, cells)
    except TypeError:
        return expr.eval(cells)


def interpolate(u: fem.Function, source):
    """u <- interpolant of a Python callable, a fem.Expression or a Function on the same mesh."""
    u.interpolate(source)
    u.x.scatter_forward()


def locate_points(msh, points):
    """Index of a local cell (owned or ghost) containing each point of ``points`` (N, 3),
    -1 where none does (``BoundingBoxTree`` + ``compute_collisions`` up to 0.8, ``bb_tree`` +
    ``compute_collisions_points`` from 0.9 on)."""
    import dolfinx.geometry as geo
    points = np.ascontiguousarray(points, dtype=msh.geometry.x.dtype)
    tdim = msh.topology.dim
    if hasattr(geo, "bb_tree"):
        candidates = geo.compute_collisions_points(geo.bb_tree(msh, tdim), points)
    else:
        candidates = geo.compute_collisions(geo.BoundingBoxTree(msh, tdim), points)
    colliding = geo.compute_colliding_cells(msh, candidates, points)
    cells = np.full(len(points), -1, dtype=np.int32)
    for i in range(len(points)):
        links = colliding.links(i)
        if len(links):
            cells[i] = links[0]
    return cells


# ---------------------------------------------------------------------------- meshes
def create_rectangle(comm, p0, p1, n, diagonal: str = "right"):
    return dmesh.create_rectangle(comm, [np.asarray(p0, float), np.asarray(p1, float)], list(n),
                                  dmesh.CellType.triangle,
                                  diagonal=getattr(dmesh.DiagonalType, diagonal))


def create_box(comm, p0, p1, n):
    """Structured box (p0, p1) with n = (nx, ny, nz) hexahedra, each cut into 6 tetrahedra."""
    return dmesh.create_box(comm, [np.asarray(p0, float), np.asarray(p1, float)], list(n),
                            dmesh.CellType.tetrahedron)


def create_tet_mesh(comm, cells, x):
    """P1 tetrahedral mesh from this rank's cells (int64 global vertex numbers) and this rank's
    block of vertex coordinates ``x`` (rank r's rows are the vertices offset_r, offset_r + 1, ...,
    offsets in rank order), partitioned and ghosted (shared facets) like ``create_box``."""
    mode = dmesh.GhostMode.shared_facet
    cells = np.asarray(cells, dtype=np.int64).reshape(-1, 4)
    x = np.asarray(x, dtype=np.float64).reshape(-1, 3)
    if "domain" in inspect.signature(dmesh.create_mesh).parameters:  # 0.5-0.6
        domain = ufl.Mesh(ufl.VectorElement("Lagrange", ufl.tetrahedron, 1))
        return dmesh.create_mesh(comm, cells, x, domain, ghost_mode=mode)
    import basix.ufl
    domain = ufl.Mesh(basix.ufl.element("Lagrange", "tetrahedron", 1, shape=(3,)))
    try:
        partitioner = dmesh.create_cell_partitioner(mode, 2)  # 0.10+: max facet-cell links
    except TypeError:
        partitioner = dmesh.create_cell_partitioner(mode)
    return dmesh.create_mesh(comm, cells=cells, x=x, e=domain, partitioner=partitioner)


def create_submesh(msh, dim, entities):
    """Submesh of the given entities; returns the mesh only (maps differ between versions)."""
    out = dmesh.create_submesh(msh, dim, entities)
    return out[0]


def locate_entities_boundary(msh, dim, marker):
    msh.topology.create_connectivity(dim, msh.topology.dim)
    return dmesh.locate_entities_boundary(msh, dim, marker)


def locate_entities(msh, dim, marker):
    return dmesh.locate_entities(msh, dim, marker)


def cell_diameters(msh, cells):
    """Largest vertex distance of the given local cells (NumPy; 0.5.2's ``cpp.mesh.h`` refuses
    the Python Mesh)."""
    g = msh.geometry.dofmap
    arr = g.array.reshape(-1, g.links(0).size) if hasattr(g, "array") else np.asarray(g)
    xs = msh.geometry.x[arr[np.asarray(cells, dtype=np.int64)]]
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
    nc = num_owned_cells(msh)
    dms = getattr(msh.geometry, "dofmaps", None)  # 0.10+: one dofmap per cell type
    dm = (dms(0) if callable(dms) else dms[0]) if dms is not None else msh.geometry.dofmap
    conn = dm.array.reshape(-1, dm.links(0).size)[:nc] if hasattr(dm, "array") else dm[:nc]
    return msh.geometry.x[conn][:, :, :2]


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


# ---------------------------------------------------------------------------- output
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
    from damage_dolfinx.geometries import gmsh_session
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


def bc_dofs(bc):
    """Local (unrolled, i.e. scalar) dof indices of a DirichletBC, owned and ghost."""
    return bc.dof_indices()[0]


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


# ---------------------------------------------------------------------------- PETSc options
_PETSC_LIBRARY = []


def petsc_option_used(name: str):
    """Whether a solver read the PETSc option ``name`` (no leading dash) since it was set
    (PetscOptionsUsed; petsc4py 3.18 has no binding for it), or None where the PETSc library
    cannot be found."""
    import ctypes
    if not _PETSC_LIBRARY:
        path = None
        try:
            with open("/proc/self/maps") as maps:
                path = next((line.split()[-1] for line in maps
                             if "/libpetsc" in line and ".so" in line), None)
        except OSError:
            pass
        try:
            _PETSC_LIBRARY.append(ctypes.CDLL(path) if path else None)
        except OSError:
            _PETSC_LIBRARY.append(None)
    lib = _PETSC_LIBRARY[0]
    if lib is None or not hasattr(lib, "PetscOptionsUsed"):
        return None
    flag = ctypes.c_int(0)
    if lib.PetscOptionsUsed(None, name.encode(), ctypes.byref(flag)) != 0:
        return None
    return bool(flag.value)
