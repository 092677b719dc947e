"""Solver defaults by dimension and size: below a size, direct factorisations; above it,
iterative solvers whose cost grows about linearly with the mesh.

The rule lives in one function, :func:`iterative`: a system is solved by CG + algebraic
multigrid when the global number of unknowns of its space is at least ``AMG_MIN_DOFS[dim]``
(measured crossovers, docs/solvers.md; overridable per solver by ``-<prefix>amg_min_dofs N``).
Below that size the package's direct defaults are kept unchanged (they serve the thesis meshes
well). Above it:

* elasticity (2.1 (2.21), its 3-D extension) and the velocity step of 3.1 (3.48): CG +
  smoothed-aggregation AMG (PETSc GAMG) with the rigid-body near-nullspace (3 modes in 2-D:
  2 translations, 1 rotation; 6 in 3-D), CG started from the previous step's solution. A
  constant matrix (3.1) is set up once; a matrix that changes every step (2.1, with zeta_n)
  keeps the AMG hierarchy of an earlier step while CG needs at most ``MECH_AMG_REBUILD_ITS``
  iterations (the lagged scheme of ``LinearSolver``; ``-<prefix>amg_rebuild_its N`` moves the
  bound; measured against rebuilding every step in docs/solvers.md);
* the damage PDE step (M + k kappa K, SPD, constant for a fixed k): CG + AMG, set up once
  (hypre BoomerAMG where PETSc has it, else GAMG).

Every choice is a code default under the solver's options prefix, so ``-mech_pc_type hypre``,
``-damage_pc_type jacobi`` or ``-mech_ksp_type preonly -mech_pc_type lu`` on the command line win.
"""
from __future__ import annotations

import numpy as np
from petsc4py import PETSc

#: the smallest system (global unknowns of its function space) solved by CG + AMG, by
#: dimension of the mesh; smaller systems are factorised (docs/solvers.md: how they were chosen)
#: 2-D: at 1e6 unknowns a factorised run is cheaper than CG + GAMG unless it is very short
#: (measured: docs/solvers.md, "Why 2 000 000 in 2-D"); the factorisation's time and memory,
#: which grow faster than N, decide above: 2e6.
AMG_MIN_DOFS = {2: 2_000_000, 3: 3000}
#: the 3-D threshold under its former name
DIRECT_MAX_DOFS_3D = AMG_MIN_DOFS[3]
#: CG iterations above which the reused elasticity AMG hierarchy is rebuilt
MECH_AMG_REBUILD_ITS = 40
#: the PETSc option (after the solver's prefix) that replaces AMG_MIN_DOFS for that solver
MIN_DOFS_OPTION = "amg_min_dofs"
#: the PETSc option (after the prefix) that replaces MECH_AMG_REBUILD_ITS (0: a new AMG set-up
#: every solve, for measurements)
REBUILD_ITS_OPTION = "amg_rebuild_its"


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


def amg_min_dofs(dim: int, prefix: str = "") -> int:
    """The threshold of :func:`iterative` for a solver with options prefix ``prefix``:
    ``-<prefix>amg_min_dofs N`` where given, else ``AMG_MIN_DOFS[dim]``. A value that is no
    whole number >= 0 is an InputError."""
    return _whole_option(prefix, MIN_DOFS_OPTION, AMG_MIN_DOFS[dim], "unknowns")


def amg_rebuild_its(prefix: str = "") -> int:
    """CG iterations above which a lagged AMG hierarchy is rebuilt: ``-<prefix>amg_rebuild_its
    N`` where given, else ``MECH_AMG_REBUILD_ITS``; 0 sets AMG up afresh at every solve."""
    return _whole_option(prefix, REBUILD_ITS_OPTION, MECH_AMG_REBUILD_ITS, "iterations")


def _whole_option(prefix: str, option: str, default: int, what: str) -> int:
    """``-<prefix><option> N`` (a whole number >= 0) where given, else ``default``; any other
    value is an InputError."""
    name = prefix + option
    opts = PETSc.Options()
    if not prefix or not opts.hasName(name):
        return default
    raw = opts.getString(name, "")  # read: PETSc counts the option as used
    try:
        value = float(raw)
    except ValueError:
        value = float("nan")
    if not (value >= 0 and value == int(value)):
        from damage_dolfinx.core.parameters import InputError
        raise InputError(f"-{name} must be a whole number of {what} >= 0, got {raw!r}")
    return int(value)


def iterative(V, prefix: str = "") -> bool:
    """The rule: CG + AMG for a system on V when V has at least ``amg_min_dofs`` global
    unknowns for its mesh's dimension (and the solver's ``-<prefix>amg_min_dofs``)."""
    dim = V.mesh.topology.dim
    return global_dofs(V) >= amg_min_dofs(dim, prefix)


def mech_config(V, direct_defaults, direct_refactor_its, prefix: str = "mech_"):
    """(defaults, refactor_after_its) of an elasticity LinearSolver on V."""
    if iterative(V, prefix):
        return MECH_AMG, amg_rebuild_its(prefix)
    return direct_defaults, direct_refactor_its


def constant_config(V, direct_defaults, prefix: str = "mech_"):
    """KSP defaults of an elasticity-like system with a constant matrix on V (3.1's velocity):
    CG + GAMG on the rigid-body modes, set up once, above the size of :func:`iterative`."""
    return MECH_AMG if iterative(V, prefix) else direct_defaults


def damage_config(Z, prefix: str = "damage_"):
    """KSP defaults of the damage PDE step on Z (None: the package's direct default)."""
    return damage_amg() if iterative(Z, prefix) else None


def prepare_mech(solver, V):
    """Give the elasticity matrix its rigid-body near-nullspace (used by GAMG, also when the
    user picks it by options; a factorisation ignores it) and, for a Krylov solve on AMG, start
    from the previous step's solution. The 2-D direct defaults are left exactly as they are
    (their CG on a lagged factorisation starts from zero)."""
    solver.A.setNearNullSpace(rigid_body_modes(V))
    pc_type = solver.ksp.getPC().getType()
    if solver.ksp.getType() != "preonly" and (V.mesh.topology.dim == 3 or
                                              pc_type not in ("lu", "cholesky")):
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
