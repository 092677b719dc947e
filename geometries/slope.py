"""Block on a sloping plane held by a downslope obstacle (thesis 3.2 Example 3, Figure 3.13;
docs/models.md, section 3.2).

The thesis gives no dimensions. We take Omega = (0, L) x (0, H) (default 2 x 1) in axes aligned
with the slope: x_1 runs up the slope, x_2 along its outward normal. The body rests on the plane
(bottom [0, L] x {0}) and leans on an obstacle perpendicular to the plane (left side
{0} x [0, H]); both are Gamma_C (bilateral contact with Tresca friction), Gamma_D is empty and
the top and right sides are free. Gravity g_0 acting straight down on a 45-degree slope becomes
the body force -(g_0/sqrt 2)(1, 1) in these axes.

The mesh is the structured rectangle of rectangle.py (n_x x n_y squares, diagonals right), so
meshes with n and 2n cells per unit length are nested. The picture of the physical setting is
obtained by rotating x by ``SLOPE_ANGLE`` with :func:`to_physical` (the package draws the
slope-aligned frame).
"""
import math

import numpy as np

from damage_dolfinx.geometries import GAMMA_C, Geometry
from damage_dolfinx.geometries.rectangle import rectangle, side

#: inclination of the plane (thesis: 45 degrees)
SLOPE_ANGLE = math.pi / 4


def slope_block(comm, n: int, length: float = 2.0, height: float = 1.0) -> Geometry:
    """The block with ``n`` cells per unit length (n = 20 gives the 40 x 20 mesh)."""
    nx, ny = int(round(n * length)), int(round(n * height))
    contact = lambda x: side(1, 0.0)(x) | side(0, 0.0)(x)  # noqa: E731  plane and obstacle
    geometry = rectangle(comm, (0.0, 0.0), (length, height), nx, ny, {GAMMA_C: contact})
    geometry.description = (f"block (0,{length:g})x(0,{height:g}) in slope-aligned axes "
                            f"(45-degree plane), {nx}x{ny} grid, diagonals right; Gamma_C = "
                            "bottom (plane) + left side (obstacle)")
    return geometry


def to_physical(x, angle: float = SLOPE_ANGLE):
    """Slope-aligned coordinates (..., 2) -> physical ones (x_1 up the slope at ``angle``)."""
    c, s = math.cos(angle), math.sin(angle)
    x = np.asarray(x)
    return np.stack([c * x[..., 0] - s * x[..., 1], s * x[..., 0] + c * x[..., 1]], axis=-1)
