"""Dirichlet conditions from facet tags: clamped parts (u = 0) and bilateral contact
(u.nu = 0 on axis-parallel Gamma_C parts, a condition on the normal Cartesian component)."""
from __future__ import annotations

import numpy as np
from dolfinx import fem

from . import compat


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
