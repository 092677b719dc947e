"""Dirichlet conditions from facet tags: clamped parts (u = 0) and bilateral contact
(u.nu = 0 on axis-parallel Gamma_C parts, a condition on the normal Cartesian component)."""
from __future__ import annotations

import numpy as np
from dolfinx import fem

from damage_dolfinx import compat


def clamped(V, facet_tags, tag):
    """u = 0 on the facets tagged ``tag`` (no condition if there are none); any dimension."""
    tdim = V.mesh.topology.dim
    V.mesh.topology.create_connectivity(tdim - 1, tdim)
    facets = facet_tags.indices[facet_tags.values == tag]
    dofs = fem.locate_dofs_topological(V, tdim - 1, facets)
    return fem.dirichletbc(np.zeros(tdim, dtype=compat.ScalarType), dofs, V)


def normal_component_zero(V, facet_tags, tag, tol=1e-10):
    """v.nu = 0 on the tagged facets, which must be horizontal (fixes v_2) or vertical (v_1)."""
    msh = V.mesh
    msh.topology.create_connectivity(1, 2)
    facets = facet_tags.indices[facet_tags.values == tag]
    xy = compat.facet_vertex_coords(msh, facets)
    d = np.abs(xy[:, 1] - xy[:, 0])
    horizontal, vertical = d[:, 1] <= tol * (1 + d[:, 0]), d[:, 0] <= tol * (1 + d[:, 1])
    if not np.all(horizontal | vertical):
        raise ValueError("bilateral contact is implemented on axis-parallel sides only")
    bcs = []
    for component, selected in ((1, horizontal), (0, vertical)):
        dofs = fem.locate_dofs_topological(V.sub(component), 1, facets[selected])
        bcs.append(fem.dirichletbc(compat.ScalarType(0.0), dofs, V.sub(component)))
    return bcs


def bilateral_plane_faces(V, facet_tags, tag, tol=1e-10):
    """u.nu = 0 on the tagged facets (bilateral contact / roller), any dimension; every tagged
    facet must lie in a coordinate plane x_a = const (its component a is fixed). No condition
    (an empty list) when no rank has such a facet. In 2-D this is ``normal_component_zero``."""
    msh = V.mesh
    facets = facet_tags.indices[facet_tags.values == tag]
    if msh.comm.allreduce(facets.size) == 0:
        return []
    if msh.topology.dim == 2:
        return normal_component_zero(V, facet_tags, tag, tol)
    xyz = compat.facet_coords(msh, facets)
    spread = xyz.max(axis=1) - xyz.min(axis=1)              # (facets, gdim)
    size = spread.max(axis=1, keepdims=True)
    in_plane = spread <= tol * (1.0 + size)                 # constant coordinate a
    if not np.all(in_plane.sum(axis=1) == 1):
        raise ValueError("bilateral contact is implemented on faces in coordinate planes only")
    bcs = []
    for a in range(msh.topology.dim):
        dofs = fem.locate_dofs_topological(V.sub(a), msh.topology.dim - 1, facets[in_plane[:, a]])
        bcs.append(fem.dirichletbc(compat.ScalarType(0.0), dofs, V.sub(a)))
    return bcs
