"""Function spaces, element queries and interpolation.

Version-specific calls only (damage_dolfinx.compat); imported from there."""
from __future__ import annotations

import numpy as np
import ufl
import ffcx
import dolfinx
from dolfinx import fem


def settle_coordinate_element(msh):
    """Give the mesh's UFL coordinate element the equispaced variant FFCx 0.5 gives it in place
    the first time it compiles a form on the mesh (ffcx.analysis). That rewrite changes the
    repr, hence the hash, of every UFL Argument made afterwards on the mesh's spaces, and UFL
    refuses a form holding an Argument made before it and one made after ("Found different
    Arguments with same number and part", e.g. a solver built again from forms already
    compiled, with test functions of its own). Done when a space is made (before its
    Arguments), the first compile changes nothing. A no-op where the element already has a
    variant and on later versions (basix.ufl coordinate elements)."""
    domain = msh.ufl_domain()
    element = getattr(domain, "_ufl_coordinate_element", None)
    sub = getattr(element, "_sub_element", None)
    if (not isinstance(element, getattr(ufl, "VectorElement", ())) or sub is None
            or getattr(sub, "_variant", "") is not None):
        return
    domain._ufl_coordinate_element = ufl.VectorElement(ufl.FiniteElement(
        sub.family(), sub.cell(), sub.degree(), sub.quadrature_scheme(), variant="equispaced"))


def function_space(msh, family: str, degree: int, shape: tuple = ()):
    """Lagrange/DG space with value shape () (scalar), (gdim,) (vector) or (gdim, gdim); the
    mesh's coordinate element settled first (:func:`settle_coordinate_element`)."""
    settle_coordinate_element(msh)
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


def affine_simplex(msh) -> bool:
    """True when the mesh's cells are simplices with an affine (degree 1) coordinate map, so
    that gradients of P1 functions are constant on each cell (UFL's own test; False where it
    cannot tell)."""
    try:
        return bool(msh.ufl_domain().is_piecewise_linear_simplex_domain())
    except (AttributeError, TypeError):
        return False


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


def interpolation_points(V):
    pts = V.element.interpolation_points
    return pts() if callable(pts) else pts


def expression(expr, V):
    """A compiled fem.Expression of ``expr`` at the interpolation points of V (the user's root
    logger kept: core/logs.py)."""
    from damage_dolfinx.core.logs import root_kept
    with root_kept(quiet=True):
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
