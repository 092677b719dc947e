"""Geometries of the thesis examples. Each builder returns a :class:`Geometry` whose facet tags
mark Gamma_D, Gamma_N and Gamma_C with the tags below."""
from dataclasses import dataclass
from typing import Optional

GAMMA_D, GAMMA_N, GAMMA_C = 1, 2, 3


@dataclass
class StructuredGrid:
    """The n_x x n_y grid (diagonals 'right') a structured mesh was cut from; meshes on grids
    with nested spacing are nested, which the convergence studies use."""
    x0: float
    y0: float
    Lx: float
    Ly: float
    nx: int
    ny: int


@dataclass
class Geometry:
    mesh: object
    facet_tags: object
    h: float                           # characteristic (maximal) cell diameter
    grid: Optional[StructuredGrid] = None
    description: str = ""
    names: Optional[dict] = None       # gmsh physical names of the facet tags: {name: tag}


_gmsh_ready = False


class _LazyGmsh:
    """The gmsh module, imported on first use: importing it costs about 0.3 s, which a run on
    a built-in mesh never needs (the geometry modules are imported with the catalogue)."""

    def __getattr__(self, name):
        return getattr(_gmsh(), name)


def _gmsh():
    """The gmsh module, imported keeping the SIGINT handler (runtime.signals)."""
    from damage_dolfinx.runtime.signals import import_gmsh_keeping_sigint
    import_gmsh_keeping_sigint()
    import gmsh
    return gmsh


#: ``from damage_dolfinx.geometries import lazy_gmsh as gmsh`` in the gmsh-built geometries
lazy_gmsh = _LazyGmsh()


def gmsh_session():
    """Initialise gmsh once per process (gmsh 4.8 has no isInitialized) and silence it."""
    global _gmsh_ready
    gmsh = _gmsh()
    if not _gmsh_ready:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        _gmsh_ready = True
    return gmsh


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
