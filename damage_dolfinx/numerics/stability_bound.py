"""A time-step limit that needs no eigensolve, and the cache of the eigensolved one
(docs/models.md, "Stability of the explicit terms: the cheap sufficient test").

Stability of the explicit terms holds iff Q(k) = 4 M + 2 k C - k^2 (K_B + K_c) > 0 with
C = K_B/m_visc (stability.py). Two upper bounds,

    K_B <= w_B M,   K_c <= w_c M,

give Q(k) >= (4 - max(0, k^2 - 2k/m_visc) w_B - k^2 w_c) M (for k <= 2/m_visc the viscous term
dominates K_B), so every k below the root k_lower of the bracket is stable: k_lower <= k_max.

The bounds (P1 on simplices, rho > 0 constant): the element mass of a d-simplex is
M_e = rho |e| / ((d+1)(d+2)) (I + 1 1^T) and its lumped (row-sum) mass L_e = rho |e|/(d+1) I, so
M_e - L_e/(d+2) = rho |e| / ((d+1)(d+2)) 1 1^T >= 0 and, summed, M >= L/(d+2) (on the free dofs
too: dropping Dirichlet columns only lowers the row sums). Hence
lam_max(A, M) <= (d+2) lam_max(A, L) <= (d+2) max_i sum_j |A_ij| / L_ii (Gershgorin on L^-1 A).
On 3.1 Ex. 1 and 3.3 Ex. 1 the bound of w_B is 1.47 times omega^2_max (k_lower >= 0.83 of the
undamped 2/omega).
"""
from __future__ import annotations

import hashlib
import math
from contextlib import contextmanager

import numpy as np
from dolfinx import mesh as dmesh
from mpi4py import MPI
from petsc4py import PETSc

#: eigensolved results of this process by a hash of the assembled K_B, K, M, m_visc and the
#: method (stability_cache.py keeps them on disk for other processes): a restart, the points of
#: a sweep and the levels of a convergence study on the same mesh and data solve the
#: eigenproblems once
_CACHE: dict = {}
_EXACT = {"on": False}

_SIMPLEX_D = {dmesh.CellType.interval: 1, dmesh.CellType.triangle: 2,
              dmesh.CellType.tetrahedron: 3}


@contextmanager
def exact_estimates():
    """Within it the eigensolve runs even where the cheap test decides (studies of k_max)."""
    previous, _EXACT["on"] = _EXACT["on"], True
    try:
        yield
    finally:
        _EXACT["on"] = previous


def exact_requested() -> bool:
    return _EXACT["on"]


def lumping_factor(V) -> float | None:
    """d + 2 for P1 (vector or scalar) on simplices, None otherwise (no bound then)."""
    msh = V.mesh
    d = _SIMPLEX_D.get(msh.topology.cell_type)
    if d is None or V.dofmap.index_map.size_global != msh.topology.index_map(0).size_global:
        return None
    return float(d + 2)


def _row_sums(A: PETSc.Mat, absolute: bool):
    indptr, _, vals = A.getValuesCSR()
    n = len(indptr) - 1
    rows = np.repeat(np.arange(n), np.diff(indptr))
    return np.bincount(rows, np.abs(vals) if absolute else vals, minlength=n), vals


def omega2_upper(A: PETSc.Mat, M: PETSc.Mat, free: np.ndarray, factor: float) -> float:
    """factor * max_i sum_j |A_ij| / sum_j M_ij over the free rows (module docstring): an upper
    bound of the largest eigenvalue of (A, M) when M is a P1 mass matrix; inf where M has a
    negative entry or a free row without mass."""
    comm = A.getComm().tompi4py()
    s, _ = _row_sums(A, True)
    m, mvals = _row_sums(M, False)
    ok = not (mvals.size and mvals.min() < 0.0) and bool(np.all(m[free] > 0.0))
    local = float(np.max(s[free] / m[free])) if ok and np.any(free) else 0.0
    if not comm.allreduce(ok, op=MPI.LAND):
        return math.inf
    return factor * comm.allreduce(local, op=MPI.MAX) * (1.0 + 1e-12)


def k_lower(w_B: float, w_c: float, m_visc: float) -> float:
    """The root of 4 - max(0, k^2 - 2k/m) w_B - k^2 w_c (module docstring); inf if none."""
    inv_m = 0.0 if math.isinf(m_visc) else 1.0 / m_visc
    if not math.isfinite(w_B) or not math.isfinite(w_c):
        return 0.0
    if w_B + w_c <= 0.0:
        return math.inf
    if w_c > 0.0 and 2.0 / math.sqrt(w_c) <= 2.0 * inv_m:
        return 2.0 / math.sqrt(w_c)  # the viscous term dominates K_B up to there
    s = w_B + w_c
    return (w_B * inv_m + math.sqrt((w_B * inv_m) ** 2 + 4.0 * s)) / s


def bound(V, K_B, K, M, m_visc, free) -> dict:
    """k_lower of the module docstring with the Gershgorin bounds of K_B and K_c = K - K_B;
    {} when the space is not P1 on simplices."""
    factor = lumping_factor(V)
    if factor is None:
        return {}
    w_B = omega2_upper(K_B, M, free, factor)
    w_c = 0.0
    if K is not K_B:
        K_c = K.duplicate(copy=True)
        K_c.axpy(-1.0, K_B, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
        w_c = omega2_upper(K_c, M, free, factor)
        K_c.destroy()
    return {"omega2_B_upper": w_B, "omega2_contact_upper": w_c,
            "k_max_lower_bound": k_lower(w_B, w_c, m_visc)}


def key(matrices, *data) -> str:
    """A hash of the assembled matrices (mesh, spaces, material, contact and Dirichlet rows all
    enter them) and of ``data``, the same on every rank."""
    h = hashlib.sha1(repr(data).encode())
    for A in matrices:
        indptr, cols, vals = A.getValuesCSR()
        for a in (indptr, cols, vals):
            h.update(np.ascontiguousarray(a).tobytes())
    comm = matrices[0].getComm().tompi4py()
    return hashlib.sha1("".join(comm.allgather(h.hexdigest())).encode()).hexdigest()


def cached(k: str):
    return _CACHE.get(k)


def store(k: str, value: dict):
    _CACHE[k] = dict(value)


def k_upper(K_B, K, M, m_visc, free) -> float:
    """A cheap upper bound of k_max, the converse of :func:`bound`: for a unit vector e_i,
    e_i^T Q(k) e_i = 4 M_ii + 2k K_B,ii/m_visc - k^2 K_ii < 0 for k above the root
    (c + sqrt(c^2 + 4 a m))/a (a = K_ii, c = K_B,ii/m_visc, m = M_ii), so Q(k) is not positive
    there and k_max is below it; the smallest root over the free rows (inf: none). Also
    returns max_i K_ii/M_ii, a lower bound of omega^2_max (a Rayleigh quotient)."""
    comm = K.getComm().tompi4py()
    a, m = K.getDiagonal().getArray(), M.getDiagonal().getArray()
    b = K_B.getDiagonal().getArray() if K_B is not K else a
    inv_m = 0.0 if math.isinf(m_visc) else 1.0 / m_visc
    use = free & (a > 0) & (m > 0)
    c = b[use] * inv_m
    roots = (c + np.sqrt(c * c + 4.0 * a[use] * m[use])) / a[use]
    local = float(roots.min()) if roots.size else math.inf
    rayleigh = float((a[use] / m[use]).max()) if roots.size else 0.0
    return comm.allreduce(local, op=MPI.MIN), comm.allreduce(rayleigh, op=MPI.MAX)


def cached_problem(value: dict, key_: str, bounds: dict, upper: tuple, m_visc: float,
                   critical, safety: float) -> str | None:
    """Why a stored stability result cannot be believed (None: it can): it must be stored under
    its own key, its numbers finite and positive, consistent with each other (the
    proportional formula of its omega^2, k_suggested = SAFETY k_max) and within the cheap
    bounds of this mesh and data: max K_ii/M_ii <= omega^2_max <= the Gershgorin bound and
    k_max_lower_bound <= k_max <= :func:`k_upper`. An entry edited, copied under another key
    or made by a defective solve is not used (the eigensolve runs again)."""
    if value.get("key") != key_:
        return "it is not stored under its own key"
    fields = ("omega2_max", "k_max", "k_max_proportional_formula", "k_suggested")
    for name in fields:
        v = value.get(name)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) \
                or v <= 0:
            return f"its {name} is {v!r}"
    slack = 1e-3  # the eigensolve's tolerance (stability.EIG_TOL) and the iteration's
    omega2, k_max = value["omega2_max"], value["k_max"]
    k_top, rayleigh = upper
    w = bounds.get("omega2_B_upper", math.inf) + bounds.get("omega2_contact_upper", 0.0)
    if omega2 < rayleigh * (1 - slack) or (math.isfinite(w) and omega2 > w * (1 + slack)):
        return (f"its omega^2_max = {omega2:.6g} lies outside [{rayleigh:.6g}, {w:.6g}], the "
                "cheap bounds of this mesh and data")
    prop = critical(omega2, m_visc)
    if abs(value["k_max_proportional_formula"] - prop) > slack * prop:
        return "its proportional formula does not follow from its omega^2_max"
    lower = bounds.get("k_max_lower_bound", 0.0)
    if k_max < lower * (1 - slack) or k_max > k_top * (1 + slack):
        return (f"its k_max = {k_max:.6g} lies outside [{lower:.6g}, {k_top:.6g}], the cheap "
                "bounds of this mesh and data")
    if abs(value["k_suggested"] - safety * k_max) > slack * k_max:
        return "its k_suggested is not SAFETY k_max"
    return None
