"""Geometries of the thesis examples. Each builder returns a :class:`Geometry` whose facet tags
mark Gamma_D, Gamma_N and Gamma_C with the tags below."""
from damage_dolfinx.compat.gmsh import gmsh_session, lazy_gmsh  # noqa: F401
from damage_dolfinx.core.geometry import Geometry, StructuredGrid  # noqa: F401
from damage_dolfinx.core.tags import GAMMA_C, GAMMA_D, GAMMA_N  # noqa: F401


def generate_2d(h):
    """Mesh the current gmsh model in 2D with element size h (transfinite curves ignore it); the
    global size options are restored afterwards."""
    gmsh = gmsh_session()
    names = ("Mesh.MeshSizeMin", "Mesh.MeshSizeMax")
    saved = [gmsh.option.getNumber(n) for n in names]
    for n in names:
        gmsh.option.setNumber(n, h)
    try:
        gmsh.model.mesh.generate(2)
    finally:
        for n, v in zip(names, saved):
            gmsh.option.setNumber(n, v)


def read_msh(comm, path) -> Geometry:
    """A gmsh .msh file whose physical curve tags follow GAMMA_D/GAMMA_N/GAMMA_C."""
    from damage_dolfinx import compat
    msh, _, facet_tags = compat.read_msh(comm, str(path))
    return Geometry(msh, facet_tags, h=float("nan"), description=f"gmsh file {path}")
