"""Time-step limit of the explicit elastic/contact force (docs/models.md, "Stability of the
explicit terms").

The dynamic schemes of Sections 3.1-3.3 (and the quasistatic one of 2.2) take the elastic force,
and in 3.1/3.3 the contact force, from step n-1 while inertia and viscosity are implicit:

    M (v_n - v_{n-1})/k + C v_n + K u_{n-1} = f_n,   u_n = u_{n-1} + k v_n,

M = (rho u, w) (mass), C = (B eps(u), eps(w))/m_visc (viscosity), K = K_B + K_c with
K_B = (B eps(u), eps(w)) and K_c = c_nu int_{Gamma_C} (u.nu)(w.nu) ds (normal compliance
linearised with the whole of Gamma_C in contact; damage and Phi_L only lower K, so the limit of
the undamaged body is conservative). The amplification factors z of one step solve
M (z - 1)^2 + k z (z - 1) C + k^2 z K = 0; on |z| = 1 this is possible only at z = -1, so the
scheme is stable iff

    Q(k) = 4 M + 2 k C - k^2 K   is positive definite.

* Proportional damping (C = K/m_visc, no contact): mode by mode e k^2 - 2 (e/m) k - 4 mm < 0,
  k_max = 1/m + sqrt(1/m^2 + 4/omega^2), omega^2 = largest eigenvalue of K x = lam M x
  (:func:`critical_time_step`; m_visc = inf: 2/omega).
* With contact C is no longer proportional to K (the contact stiffness is undamped) and the
  least damped stiff mode decides: Q(k) > 0 iff k^2 g(k) < 1 with g(k) the largest eigenvalue
  of K x = g (4 M + 2 k C) x. k^2 g(k) increases with k; its root lies between 2/omega and the
  closed form above, and is found by false position in log k (:func:`k_max_nonproportional`,
  4-6 eigensolves). For 3.1 Ex. 1 this gives k_max = 0.0129-0.0146 (n = 128 ... 4) where the
  closed form says 0.2; the onsets of chatter seen in runs lie within 4 % above it.

Cheap first (:func:`estimate_stability`): a lower bound of k_max with no eigensolve
(stability_bound.py); the eigenvalues below only when the time step is above it.

Eigenvalues (:func:`largest_eigenvalue`): SLEPc Krylov-Schur (GHEP, options prefix
``stability_``) when slepc4py can be imported, else power iteration with one MUMPS factorisation
of M; both handle Dirichlet rows (see there).
"""
from __future__ import annotations

import math
import sys

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from damage_dolfinx import compat
from damage_dolfinx.numerics import stability_bound, stability_cache
from damage_dolfinx.forms.constitutive import B, eps
from damage_dolfinx.core.parameters import InputError

#: safety factor of the suggested time step (0.8 k_max)
SAFETY = 0.8

#: PETSc/SLEPc options prefix of the eigenvalue solvers
PREFIX = "stability_"

#: residual tolerance of the eigensolves inside estimate_stability: the eigenvalue error is of
#: the order of the squared residual, k_max ~ omega^-1; on 3.1 Ex. 1 it gives the k_max of a
#: tolerance of 1e-4 to 1e-9, in less time (benchmarks/README.md, "Why the defaults")
EIG_TOL = 1e-3


# ---------------------------------------------------------------------------- closed forms
def critical_time_step(omega2_max: float, m_visc: float) -> float:
    """k_max = 1/m + sqrt(1/m^2 + 4/omega^2) (proportional damping); m_visc = inf gives 2/omega,
    omega^2 = 0 gives inf (no explicit stiffness)."""
    if not omega2_max > 0:
        return math.inf
    inv_m = 0.0 if math.isinf(m_visc) else 1.0 / m_visc
    return inv_m + math.sqrt(inv_m**2 + 4.0 / omega2_max)


def check_time_step(k: float, k_max: float, where: str, action: str = "warn") -> float:
    """Compare k with k_max; returns k/k_max. If k > k_max: ``warn`` prints one line on rank 0
    (k, k_max and the suggested 0.8 k_max), ``error`` raises InputError, ``off`` is silent."""
    if action not in ("warn", "error", "off"):
        raise InputError(f"stability_check must be warn, error or off, got {action!r}")
    ratio = k / k_max if k_max > 0 else math.inf
    if ratio <= 1.0 or action == "off":
        return ratio
    message = (f"time step k = {k:.4g} exceeds the stability limit k_max = {k_max:.4g} of the "
               f"scheme's explicit terms ({where}, k/k_max = {ratio:.3g}); use "
               f"k <= {SAFETY * k_max:.4g} (0.8 k_max)")
    if action == "error":
        raise InputError(message + " (problem.k_max() gives k_max before the run), or "
                         "allow_unstable=True to run it anyway")
    if MPI.COMM_WORLD.rank == 0:
        print(f"WARNING: {message}", file=sys.stderr, flush=True)
    return ratio


# ---------------------------------------------------------------------------- eigenvalues
def _isolated_rows(K: PETSc.Mat, M: PETSc.Mat) -> np.ndarray:
    """Local indices of the owned rows without off-diagonal entries in K and in M: Dirichlet
    rows assembled with bcs (rows and columns zeroed, a diagonal value put back). A free P1 dof
    always couples to its neighbours through the consistent mass matrix."""
    rstart, rend = K.getOwnershipRange()
    isolated = np.ones(rend - rstart, dtype=bool)
    for A in (K, M):
        indptr, cols, vals = A.getValuesCSR()
        rows = np.repeat(np.arange(rstart, rend), np.diff(indptr))
        off = (cols != rows) & (vals != 0.0)
        isolated &= np.bincount(rows[off] - rstart, minlength=rend - rstart) == 0
    return np.flatnonzero(isolated)


def _without_dirichlet_modes(K: PETSc.Mat, M: PETSc.Mat) -> PETSc.Mat:
    """K with a zero diagonal on isolated (Dirichlet) rows, so that they give lam = 0 whatever
    diagonal value (1 is the DOLFINx default) they were assembled with."""
    rows = _isolated_rows(K, M)
    K2 = K.duplicate(copy=True)
    if K.getComm().tompi4py().allreduce(rows.size, op=MPI.SUM) == 0:
        return K2
    d = K2.getDiagonal()
    d.getArray()[rows] = 0.0
    K2.setDiagonal(d, addv=PETSc.InsertMode.INSERT_VALUES)
    d.destroy()
    return K2


def _slepc():
    try:
        from slepc4py import SLEPc
        return SLEPc
    except ImportError:
        return None


def largest_eigenvalue(K: PETSc.Mat, M: PETSc.Mat, tol=1e-6, max_it=500, method="auto",
                       return_vector=False):
    """Largest lam of K x = lam M x (K symmetric positive semidefinite, M SPD, both assembled).

    Dirichlet rows: assemble K and M with the same bcs; any diagonal value works, because rows
    without off-diagonal entries in both matrices (the Dirichlet rows) are given K_ii = 0 here,
    i.e. lam = 0, never the largest (with K_ii = M_ii = 1 they would otherwise add a spurious
    lam = 1, which is the largest when omega^2 < 1, e.g. E = 100, rho = 2700).

    ``method``: ``slepc`` (Krylov-Schur, GHEP, shift-and-invert-free: M factorised by MUMPS;
    options prefix ``stability_``; tol = SLEPc's relative residual), ``power`` (power iteration
    on M^-1 K with one MUMPS factorisation of M and the Rayleigh quotient, stopped at the same
    relative residual or after max_it iterations: a lower bound then), ``auto``
    (slepc if importable, else power). Returns lam (and the eigenvector with
    ``return_vector=True``).
    """
    K2 = _without_dirichlet_modes(K, M)
    try:
        if method in ("auto", "slepc") and _slepc() is not None:
            out = _largest_slepc(K2, M, tol, max_it)
            if out is not None:
                return out if return_vector else out[0]
        if method == "slepc" and _slepc() is None:
            raise ImportError("slepc4py is not available; use method='power'")
        out = _largest_power(K2, M, tol, max_it)
        return out if return_vector else out[0]
    finally:
        K2.destroy()


def _factorised_ksp(M: PETSc.Mat, prefix: str) -> PETSc.KSP:
    ksp = PETSc.KSP().create(M.getComm())
    ksp.setOptionsPrefix(prefix)
    ksp.setOperators(M)
    ksp.setType("preonly")
    pc = ksp.getPC()
    pc.setType("lu")
    pc.setFactorSolverType("mumps")
    ksp.setFromOptions()
    return ksp


def _start_vector(K: PETSc.Mat) -> PETSc.Vec:
    """Deterministic pseudo-random start, a function of the global dof index."""
    x = K.createVecRight()
    lo, hi = x.getOwnershipRange()
    i = np.arange(lo, hi, dtype=float)
    x.getArray()[:] = 1.0 + 0.5 * np.sin(12.9898 * i + 78.233 * np.sin(0.37 * i))
    return x


def _largest_power(K, M, tol, max_it):
    """Power iteration x <- M^-1 K x with the Rayleigh quotient; stops when the residual
    ||M^-1 K x - lam x|| / (lam ||x||) <= tol (the eigenvalue error is of order its square)."""
    ksp = _factorised_ksp(M, PREFIX + "power_")
    x, y, z, w = _start_vector(K), K.createVecLeft(), K.createVecRight(), K.createVecRight()
    x.scale(1.0 / x.norm())
    lam = 0.0
    for _ in range(max_it):
        K.mult(x, y)
        M.mult(x, z)
        lam = y.dot(x) / z.dot(x)
        ksp.solve(y, w)                                   # w = M^-1 K x
        w.copy(z)
        z.axpy(-lam, x)
        if lam == 0.0 or z.norm() <= tol * abs(lam):
            break
        w.copy(x)
        x.scale(1.0 / x.norm())
    for obj in (ksp, y, z, w):
        obj.destroy()
    return float(lam), x


def _largest_slepc(K, M, tol, max_it):
    SLEPc = _slepc()
    E = SLEPc.EPS().create(K.getComm())
    E.setOptionsPrefix(PREFIX)
    E.setOperators(K, M)
    E.setProblemType(SLEPc.EPS.ProblemType.GHEP)
    E.setWhichEigenpairs(SLEPc.EPS.Which.LARGEST_MAGNITUDE)
    E.setDimensions(1)
    E.setTolerances(tol, max_it)
    ksp = E.getST().getKSP()
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    E.setFromOptions()
    E.solve()
    if E.getConverged() < 1:
        E.destroy()
        return None  # caller falls back to power iteration
    x = K.createVecRight()
    lam = E.getEigenpair(0, x).real
    E.destroy()
    return float(lam), x


# ---------------------------------------------------------------------------- k_max
def k_max_nonproportional(K: PETSc.Mat, M: PETSc.Mat, C: PETSc.Mat, m_visc: float, tol=1e-4,
                          max_it=30, eig_tol=EIG_TOL, method="auto", omega2=None) -> float:
    """Smallest k with Q(k) = 4M + 2kC - k^2 K singular, for symmetric K >= 0 and
    0 <= C <= K/m_visc (module docstring). Q(k) > 0 iff psi(k) = log(k^2 g(k)) < 0, g(k) the
    largest eigenvalue of K x = g (4M + 2kC) x; psi increases with k and is nearly linear in
    log k (exactly for an undamped mode). Bracket: k = 2/omega (undamped bound, omega^2 the
    largest eigenvalue of (K, M)) is stable; the proportional formula k_p =
    critical_time_step(omega^2, m_visc) is not (C <= K/m_visc gives Q(k_p) <= Q_p(k_p), singular
    on the top mode). Illinois false position in log k; one factorisation of 4M + 2kC per
    evaluation; stops when the bracket is narrower than tol (relative)."""
    def psi(log_k):
        k = math.exp(log_k)
        P = M.duplicate(copy=True)
        P.scale(4.0)
        P.axpy(2.0 * k, C, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)  # V x V dx forms
        g = largest_eigenvalue(K, P, tol=eig_tol, method=method)
        P.destroy()
        return 2.0 * log_k + math.log(g)

    if omega2 is None:
        omega2 = largest_eigenvalue(K, M, tol=eig_tol, method=method)
    if not omega2 > 0:
        return math.inf
    lo, hi = math.log(critical_time_step(omega2, math.inf)), math.log(critical_time_step(omega2, m_visc))
    f_lo, f_hi = min(psi(lo), 0.0), max(psi(hi), 0.0)  # signs hold up to the eigen tolerance
    side = 0
    for _ in range(max_it):
        if hi - lo <= tol or f_lo == 0.0:
            break
        mid = (lo * f_hi - hi * f_lo) / (f_hi - f_lo) if f_hi != f_lo else 0.5 * (lo + hi)
        f_mid = psi(mid)
        if abs(f_mid) <= tol:
            return math.exp(mid)
        if f_mid < 0.0:
            lo, f_lo = mid, f_mid
            f_hi, side = (0.5 * f_hi if side == -1 else f_hi), -1  # Illinois
        else:
            hi, f_hi = mid, f_mid
            f_lo, side = (0.5 * f_lo if side == 1 else f_lo), 1
    return math.exp(lo)


def _assembled(a, bcs) -> PETSc.Mat:
    form = compat.form(a)
    A = compat.create_matrix(form)
    compat.assemble_matrix(A, form, list(bcs))
    A.assemble()
    return A


def stiffness_and_mass(V, E, nu, rho, c_nu=0.0, dsC=None, bcs=(), normal=None):
    """(K_B, K, M) assembled on V with the Dirichlet conditions ``bcs``: K = K_B + K_c (one form
    with the cell and the facet integral, so that both share the sparsity and the Dirichlet
    rows), K is K_B itself without contact (c_nu = 0 or dsC None)."""
    u, w = ufl.TrialFunction(V), ufl.TestFunction(V)
    k_B = ufl.inner(B(eps(u), E, nu), eps(w)) * ufl.dx  # plane stress in 2-D, 3-D Hooke
    K_B = _assembled(k_B, bcs)
    M = _assembled(fem.Constant(V.mesh, float(rho)) * ufl.inner(u, w) * ufl.dx, bcs)
    K = K_B
    if c_nu and dsC is not None:
        n = ufl.FacetNormal(V.mesh) if normal is None else normal
        k_c = fem.Constant(V.mesh, float(c_nu)) * ufl.dot(u, n) * ufl.dot(w, n) * dsC
        K = _assembled(k_B + k_c, bcs)
    return K_B, K, M


def _checked_data(E, nu, rho, m_visc, c_nu):
    """The data of a stability estimate as floats (a Constant by its value), checked: a
    density or viscosity of zero or below, or a Poisson ratio outside (-1, 1/2), has no
    stable time step to estimate (the eigenproblem would fail in PETSc or divide by zero)."""
    from damage_dolfinx.core.validation import real

    def value(v):
        return float(np.asarray(v.value)) if hasattr(v, "value") else v
    E, nu, rho, m_visc, c_nu = (value(v) for v in (E, nu, rho, m_visc, c_nu))
    out = [real("E", E, low=0.0, low_open=True), real("nu", nu, low=-1.0, low_open=True),
           real("rho", rho, low=0.0, low_open=True), real("m_visc", m_visc, low=0.0,
                                                          low_open=True),
           real("c_nu", c_nu, low=0.0)]
    if not out[1] < 0.5:
        raise InputError(f"nu must be < 0.5 (Poisson's ratio), got {out[1]:g}")
    return out


def estimate_stability(V, E, nu, rho, m_visc, c_nu=0.0, dsC=None, bcs=(), normal=None,
                       method="auto", k=None) -> dict:
    """omega^2_max of (K_B + K_c, M) and the time-step limit k_max of the scheme (module
    docstring): the closed form without contact, the non-proportional iteration with it.
    ``method``: eigenvalue solver of :func:`largest_eigenvalue`.

    First the cheap sufficient test (stability_bound.py, no eigensolve): a proven lower bound
    k_max_lower_bound <= k_max. With a time step ``k`` at or below it the answer is clear and no
    eigenvalue is computed: ``k_max`` is None and ``decided_by`` is ``bound`` (inside
    stability_bound.exact_estimates() the eigensolve runs all the same). Otherwise the
    eigensolved k_max, kept in memory and on disk (stability_cache.py) by a hash of the
    matrices, m_visc and the eigen method (``decided_by``: ``eigensolve``, ``cache`` (this
    process) or ``disk cache`` (an earlier process)). The data are checked first (InputError:
    E, rho, m_visc > 0, -1 < nu < 1/2, c_nu >= 0, all finite)."""
    E, nu, rho, m_visc, c_nu = _checked_data(E, nu, rho, m_visc, c_nu)
    K_B, K, M = stiffness_and_mass(V, E, nu, rho, c_nu, dsC, bcs, normal)
    try:
        rstart, rend = K.getOwnershipRange()
        free = np.ones(rend - rstart, dtype=bool)
        free[_isolated_rows(K, M)] = False
        out = stability_bound.bound(V, K_B, K, M, m_visc, free)
        lower = out.get("k_max_lower_bound", 0.0)
        if k is not None and k <= lower and not stability_bound.exact_requested():
            return {**out, "k_max": None, "decided_by": "bound"}
        method_used = "slepc" if method != "power" and _slepc() else "power"
        key = stability_bound.key((K_B, K, M), float(m_visc), method_used, EIG_TOL,
                                  stability_cache.FORMAT)
        comm = K.getComm().tompi4py()
        exact, decided_by = stability_bound.cached(key), "cache"
        if exact is None:
            exact, decided_by = stability_cache.load(key, comm), "disk cache"
            if exact is not None:  # verified, not believed: its key and the cheap bounds
                wrong = stability_bound.cached_problem(
                    exact, key, out, stability_bound.k_upper(K_B, K, M, m_visc, free),
                    m_visc, critical_time_step, SAFETY)
                if wrong:
                    if comm.rank == 0:
                        import sys
                        print(f"WARNING: the stored stability limit {key[:12]} (the stability "
                              f"cache, {stability_cache.ENV}) is not used: {wrong}; it is "
                              "eigensolved again", file=sys.stderr, flush=True)
                    exact = None
                else:
                    stability_bound.store(key, exact)
        if exact is None:
            decided_by = "eigensolve"
            exact = _eigensolved(K_B, K, M, m_visc, method)
            exact["eigen_method"] = method_used
            stability_bound.store(key, exact)
            stability_cache.save(key, {**exact, "key": key}, comm)
        exact = {name: value for name, value in exact.items() if name != "key"}
        return {**out, **exact, "decided_by": decided_by}
    finally:
        for A in {id(a): a for a in (K_B, K, M)}.values():
            A.destroy()


#: eigensolves run in this process (what the caches save is counted here)
EIGENSOLVES = {"count": 0}


def _eigensolved(K_B, K, M, m_visc, method) -> dict:
    EIGENSOLVES["count"] += 1
    omega2 = largest_eigenvalue(K, M, tol=EIG_TOL, method=method)
    k_prop = critical_time_step(omega2, m_visc)
    if K is K_B or math.isinf(m_visc):
        k_max = k_prop
    else:
        C = K_B.duplicate(copy=True)
        C.scale(1.0 / m_visc)
        k_max = k_max_nonproportional(K, M, C, m_visc, method=method, omega2=omega2)
        C.destroy()
    return {"omega2_max": omega2, "k_max": k_max, "k_max_proportional_formula": k_prop,
            "k_suggested": SAFETY * k_max}


def checked(out: dict, k: float, where: str, action: str) -> dict:
    """check_time_step on the result of :func:`estimate_stability`: k/k_max where the
    eigensolve ran; where the bound decided, k/k_max_lower_bound (<= 1, an upper bound of
    k/k_max) and nothing to say."""
    limit = out["k_max"] if out.get("k_max") is not None else out["k_max_lower_bound"]
    out["k_over_k_max"] = check_time_step(k, limit, where, action=action)
    return out


def estimate_k_max(V, E, nu, rho, m_visc, c_nu=0.0, dsC=None, bcs=(), normal=None) -> float:
    """k_max of the explicit elastic (+ normal compliance on dsC) force on V (module docstring).

    Without contact (c_nu = 0 or dsC None) this is critical_time_step(omega^2_max, m_visc) with
    omega^2_max the largest eigenvalue of (K_B, M_rho). With contact the contact stiffness
    c_nu (u.nu)(w.nu) ds is undamped, the closed form would overestimate k_max (up to ~15x for
    3.1 Ex. 1) and the exact limit of the scheme, the smallest k with 4M + 2kC - k^2(K_B + K_c)
    singular, is returned (:func:`k_max_nonproportional`). Always eigensolved (or cached).
    """
    return estimate_stability(V, E, nu, rho, m_visc, c_nu, dsC, bcs, normal)["k_max"]
