"""Every DOLFINx-version-specific call of the package, in one place (this package).

The package targets DOLFINx 0.5.2 (Debian 12). Differences with newer releases are handled by
feature probes (``hasattr``) rather than version strings, so a port to 0.9/0.10 touches this
package only. Nothing else in the package may call an API listed here directly. The calls are
grouped by concept and all importable from here (``compat.form``, ``compat.vector_p1``, ...):

* :mod:`.spaces`: function spaces, element queries, interpolation and point evaluation;
* :mod:`.assembly`: forms, PETSc vectors and matrices, assembly, boundary conditions;
* :mod:`.meshes`: meshes, entities and tags, cell and facet geometry, gmsh and XDMF files;
* :mod:`.petsc`: PETSc options and the "unlimited" tolerance.
"""
from __future__ import annotations

from damage_dolfinx.core.logs import LOGGER, root_kept  # noqa: F401

# FFCx 0.5 configures the root logger at import (basicConfig, captureWarnings): undone (core/logs.py)
with root_kept():
    import dolfinx
    import dolfinx.fem.petsc  # noqa: F401  (0.7+ no longer imports it implicitly)
    import ffcx  # noqa: F401
from petsc4py import PETSc  # noqa: E402

DOLFINX_VERSION = dolfinx.__version__
ScalarType = getattr(dolfinx, "default_scalar_type", PETSc.ScalarType)

from damage_dolfinx.compat.spaces import (  # noqa: E402,F401
    function_space, settle_coordinate_element, element_degree, affine_simplex, is_discontinuous, scalar_p1, vector_p1,
    scalar_dg0, tensor_dg0, facet_vertex_quadrature, interpolation_points, expression,
    eval_expression, interpolate, locate_points)
from damage_dolfinx.compat.assembly import (  # noqa: E402,F401
    petsc_vec, create_vector, create_matrix, assemble_vector, assemble_vector_array,
    assemble_matrix, apply_lifting, dirichlet_values_zero, set_bc, form, assemble_scalar,
    bc_dofs)
from damage_dolfinx.compat.meshes import (  # noqa: E402,F401
    create_rectangle, create_box, create_simplex_mesh, create_tet_mesh, create_submesh,
    locate_entities_boundary,
    locate_entities, geometry_dofmap, cell_diameters, meshtags, cell_midpoints, num_owned_cells,
    cell_vertex_coords, cell_dofs, model_to_mesh, xdmf_file, read_msh,
    dofs_in_cells, facet_coords, facet_vertex_coords, geometry_input_indices, num_owned_nodes,
    dofmap_array, cell_type_name)
from damage_dolfinx.compat.petsc import (  # noqa: E402,F401
    PETSC_UNLIMITED, petsc_option_used)
