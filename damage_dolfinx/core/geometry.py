"""The geometry type: a mesh with its facet tags (see :mod:`damage_dolfinx.core.tags`)."""
from dataclasses import dataclass
from typing import Optional


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
