"""Solver defaults by dimension and size: iterative solvers whose cost grows about
linearly with the mesh, for 3-D.

2-D keeps the package's direct defaults unchanged (they serve the thesis meshes well). In 3-D:

* elasticity: CG + algebraic multigrid (PETSc GAMG) with the rigid-body near-nullspace (6 modes:
  3 translations, 3 rotations), the AMG hierarchy of an earlier step's matrix reused while CG
  needs at most ``MECH_AMG_REBUILD_ITS`` iterations (the lagged scheme of ``LinearSolver``);
* damage (M + k kappa K, SPD, constant for a fixed k): CG + AMG, set up once (hypre BoomerAMG
  where PETSc has it, else GAMG);
* very small 3-D systems (below ``DIRECT_MAX_DOFS_3D`` dofs) keep the direct defaults: there a
  factorisation costs less than an AMG setup.

Every choice is a code default under the solver's options prefix, so ``-mech_pc_type hypre``,
``-damage_pc_type jacobi`` or ``-mech_ksp_type preonly -mech_pc_type lu`` on the command line win.
"""
from __future__ import annotations

import numpy as np
from petsc4py import PETSc

#: below this many unknowns a 3-D system is factorised (direct defaults of the 2-D package)
DIRECT_MAX_DOFS_3D = 3000
#: CG iterations above which the reused elasticity AMG hierarchy is rebuilt
MECH_AMG_REBUILD_ITS = 40


def has_hypre() -> bool:
    """True when PETSc was built with hypre (checked once by creating the PC)."""
    global _HYPRE
    if _HYPRE is None:
        pc = PETSc.PC().create(PETSc.COMM_SELF)
        try:
            pc.setType("hypre")
            _HYPRE = True
        except PETSc.Error:
            _HYPRE = False
        finally:
            pc.destroy()
    return _HYPRE


_HYPRE = None

#: the Krylov part shared by the AMG defaults: true residual, relative to ||b||
_KRYLOV = {"ksp_type": "cg", "ksp_norm_type": "unpreconditioned", "ksp_rtol": 1e-10,
           "ksp_atol": 1e-50, "ksp_max_it": 500}

#: elasticity: CG + smoothed-aggregation AMG on the rigid-body near-nullspace
MECH_AMG = {**_KRYLOV, "pc_type": "gamg",
            "pc_gamg_type": "agg", "pc_gamg_agg_nsmooths": 1, "pc_gamg_threshold": 0.02,
            "mg_levels_ksp_type": "chebyshev", "mg_levels_pc_type": "jacobi",
            "mg_levels_ksp_max_it": 2}


def damage_amg() -> dict:
    """Damage systems: CG + BoomerAMG (hypre) or GAMG, AMG setup once (constant matrix)."""
    if has_hypre():
        return {**_KRYLOV, "pc_type": "hypre", "pc_hypre_type": "boomeramg"}
    return {**_KRYLOV, "pc_type": "gamg"}


def global_dofs(V) -> int:
    imap = V.dofmap.index_map
    return imap.size_global * V.dofmap.index_map_bs


def iterative(V) -> bool:
    """The rule: AMG for 3-D meshes with at least DIRECT_MAX_DOFS_3D unknowns in V."""
    return V.mesh.topology.dim == 3 and global_dofs(V) >= DIRECT_MAX_DOFS_3D


def mech_config(V, direct_defaults, direct_refactor_its):
    """(defaults, refactor_after_its) of an elasticity LinearSolver on V."""
    if iterative(V):
        return MECH_AMG, MECH_AMG_REBUILD_ITS
    return direct_defaults, direct_refactor_its


def damage_config(Z):
    """KSP defaults of the damage PDE step on Z (None: the package's direct default)."""
    return damage_amg() if iterative(Z) else None


def prepare_mech(solver, V):
    """In 3-D: give the elasticity matrix its rigid-body near-nullspace (used by GAMG, also
    when the user picks it by options) and, for a Krylov solve, start from the previous step's
    displacement. Nothing in 2-D."""
    if V.mesh.topology.dim != 3:
        return
    solver.A.setNearNullSpace(rigid_body_modes(V))
    if solver.ksp.getType() != "preonly":
        solver.ksp.setInitialGuessNonzero(True)


def rigid_body_modes(V) -> PETSc.NullSpace:
    """The near-nullspace of elasticity on the P1 vector space V: translations and rotations
    (3 in 2-D, 6 in 3-D) at the owned dofs, orthonormalised (PETSc requires it)."""
    gdim = V.mesh.topology.dim
    imap, bs = V.dofmap.index_map, V.dofmap.index_map_bs
    n_owned = imap.size_local
    x = V.tabulate_dof_coordinates()[:n_owned, :gdim]
    x = x - V.mesh.comm.allreduce(x.sum(axis=0), op=_sum()) / max(imap.size_global, 1)
    rot = [(0, 1)] if gdim == 2 else [(0, 1), (1, 2), (2, 0)]
    vectors = []
    for i in range(gdim + len(rot)):
        v = PETSc.Vec().createMPI((n_owned * bs, PETSc.DECIDE), bsize=bs, comm=V.mesh.comm)
        a = np.zeros((n_owned, bs))
        if i < gdim:
            a[:, i] = 1.0
        else:  # rotation in the (p, q) plane: (-x_q, x_p)
            p, q = rot[i - gdim]
            a[:, p], a[:, q] = -x[:, q], x[:, p]
        v.setArray(a.ravel())
        vectors.append(v)
    for i, v in enumerate(vectors):  # modified Gram-Schmidt
        for w in vectors[:i]:
            v.axpy(-v.dot(w), w)
        v.scale(1.0 / v.norm())
    return PETSc.NullSpace().create(vectors=vectors, comm=V.mesh.comm)


def _sum():
    from mpi4py import MPI
    return MPI.SUM
