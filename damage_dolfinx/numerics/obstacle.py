"""Fast path of the damage obstacle step: vinewtonrsls's first iteration with cached
linear algebra, accepted only where vinewtonrsls's own convergence test accepts it.

The obstacle problem of every step is B z >= l on K^h = {zeta_star <= z <= 1} with B = M +
k kappa K constant for a run (damage.py). PETSc's ``vinewtonrsls`` started from z0 = zeta_{n-1}

1. computes F0 = B z0 - l and the active set A = {z0 <= zeta_star + 1e-8 and F0 >= 0} u
   {z0 >= 1 - 1e-8 and F0 <= 0} (PETSc's SNESVIGetActiveSetIS: values within 1e-8 of a bound
   count as on it, the sign of F decides, an exact zero counts as active); it stops at once if
   the norm of F0 over the inactive set I is below its tolerance;
2. solves B_II y_I = F0_I (y_A = 0), sets z1 = z0 - y and projects z1 onto [zeta_star, 1];
3. stops if the norm of F1 = B z1 - l over the inactive set of (z1, F1) is <= atol or <= rtol
   times that of step 1, and iterates otherwise.

Each SNES iteration extracts B_II, sets up its preconditioner and runs CG.
:class:`ObstacleFastPath` does steps 1-3 itself: the same active set from the same (z0, F0), so
nodes within round-off of a bound are treated exactly as the SNES treats them (a value within
1e-8 of a bound is held where it is if F pushes it outward, and moves freely otherwise; this
also covers the wrench, lam_D = 0, where zeta stays within round-off of 1 for a while). Its
linear algebra is cached:

* empty active set (most steps of every problem; the wrench never reaches zeta_star): B itself,
  factorised once per run (Cholesky: PETSc's, nested dissection, serially; MUMPS's on several
  ranks; up to CHOLESKY_MAX_DOFS),
  one pair of triangular solves per step;
* otherwise B_II, extracted and given the SNES's own KSP (type, preconditioner, tolerances: the
  SNES's Newton step bit for bit) once per active set and kept while the set stays the same.

The result is accepted when

* no inactive value lies beyond a bound by more than FEASIBILITY_TOL (round-off; then it is
  projected, as the SNES projects; the SNES projects any violation and lets step 3 judge, so
  this only sends more steps to the SNES), and
* the SNES's convergence test of step 3 holds (fnorm <= atol or fnorm <= rtol fnorm0, the norms
  taken exactly as PETSc's SNESVIComputeInactiveSetFnorm takes them): a point the SNES would
  return as converged.

Otherwise the caller runs the SNES from z0 as before. Because B is SPD the VI solution is
unique, so an accepted step equals vinewtonrsls's answer to solver tolerance (with the CG it is
the SNES's answer bit for bit). The fast path keeps no state but the cached solvers; which one
a step uses depends on its active set alone, a function of (zeta_{n-1}, l): a restarted run
repeats the uninterrupted one exactly.
"""
from __future__ import annotations

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from damage_dolfinx.core.parameters import InputError

#: PETSc's vinewtonrsls counts a value within this distance of a bound as on it
VI_BOUND_WINDOW = 1e-8
#: largest violation of a bound by a free value that is projected (round-off); beyond it the
#: step goes to the SNES
FEASIBILITY_TOL = 1e-10
#: largest size (by dimension) whose full matrix B is factorised (Cholesky: PETSc's serially,
#: MUMPS's on several ranks): a solve with the factor (nested dissection, made once) costs a
#: fraction of the CG the SNES runs. The CG's iterations grow with the mesh
#: (B = M + k kappa K: its condition grows like 1/h^2), so its cost per step grows like N^1.5
#: (measured: benchmarks/README.md, "Why the defaults"). In 2-D the bound is the damage space of a
#: mesh whose vector space reaches the rule's AMG_MIN_DOFS[2] (2e6, numerics/scalable.py), whose
#: factorisations are kept to that size; 3-D factors fill faster
CHOLESKY_MAX_DOFS = {2: 1_000_000, 3: 30_000}
#: auto: Cholesky for the full B (up to CHOLESKY_MAX_DOFS), the SNES's CG for reduced
#: systems; cholesky: factorise every system (one factorisation per new active set); cg: the
#: SNES's CG for all (each accepted step then equals the SNES's bit for bit)
SOLVERS = ("auto", "cholesky", "cg")
#: after failed attempts on a nonempty active set in a row (3.1-ex1 while its zeta* region grows:
#: the SNES needs a few iterations in most steps), such attempts pause 1, 2, 4, ... up to this
#: many steps. Failed attempts on an empty set (3.3-ex2: values overshoot 1 every step) cost one
#: pair of triangular solves and never pause.
#: Only attempts whose hit equals the SNES's answer bit for bit (its CG) pause, so the pause
#: never changes a result (and a restart, which resets it, repeats the uninterrupted run).
MAX_PAUSE = 16


def fast_path_options(prefix: str):
    """(enabled, solver) from the user's ``-<prefix>vi_fast 0|1`` and
    ``-<prefix>vi_fast_solver auto|cholesky|cg``; a bad value is an InputError."""
    opts = PETSc.Options()
    flag = opts.getString(prefix + "vi_fast", "1").strip().lower()
    if flag not in ("0", "1", "true", "false", "yes", "no", "on", "off"):
        raise InputError(f"-{prefix}vi_fast must be 0 or 1, got {flag!r}")
    solver = opts.getString(prefix + "vi_fast_solver", "auto").strip().lower()
    if solver not in SOLVERS:
        raise InputError(f"-{prefix}vi_fast_solver must be one of {', '.join(SOLVERS)}, "
                         f"got {solver!r}")
    return flag in ("1", "true", "yes", "on"), solver


class ObstacleFastPath:
    """The first vinewtonrsls iteration of B z >= l on [lb, ub] with a cached reduced solver."""

    def __init__(self, B: PETSc.Mat, lb: float, ub: float, snes_ksp: PETSc.KSP,
                 solver: str = "auto", max_direct: int = CHOLESKY_MAX_DOFS[2]):
        self.B, self.lb, self.ub = B, float(lb), float(ub)
        self.comm = B.getComm().tompi4py()
        # Cholesky for the full B (once per run) up to max_direct unknowns; the reduced B_II by
        # the SNES's own CG (bit for bit its Newton step) unless asked
        self.direct_full = solver == "cholesky" or (
            solver == "auto" and B.getSize()[0] <= max_direct)
        self.direct_reduced = solver == "cholesky"
        self.snes_ksp = snes_ksp  # the CG copies its options prefix
        self.rstart = B.getOwnershipRange()[0]
        self.F, self.x1 = B.createVecLeft(), B.createVecRight()
        self.y = B.createVecRight()
        # their value arrays (stable views: the Vecs own them, fewer calls a step)
        self._x1, self._y, self._f = self.x1.array, self.y.array, self.F.array
        self._serial = self.comm.size == 1
        self._full = None  # solver of B (empty active set)
        self._key, self._cached = None, ()  # inactive mask and (KSP, rhs, y, B_II) of B_II
        self._reduced_ksp = None
        self.hits = self.fallbacks = self.setups = self.unchanged = self.skipped = 0
        self._failures = self._pause = 0  # failed attempts with a nonempty active set in a row

    def counts(self) -> dict:
        """Accepted steps (of them ``unchanged``: z0 accepted at iteration 0, no solve), steps
        handed to the SNES after an attempt (fallbacks) or without one (skipped), and solvers
        built (B once, B_II once per new active set)."""
        return {"damage_vi_fast_hits": self.hits, "damage_vi_fast_unchanged": self.unchanged,
                "damage_vi_fast_fallbacks": self.fallbacks, "damage_vi_fast_skipped": self.skipped,
                "damage_vi_fast_setups": self.setups}

    def _allsum(self, values):
        if self._serial:
            return values
        values = np.asarray(values, dtype=float)
        self.comm.Allreduce(MPI.IN_PLACE, values, op=MPI.SUM)
        return values

    @staticmethod
    def _norm_sq(f, inactive) -> float:
        """Local part of PETSc's SNESVIComputeInactiveSetFnorm (squared)."""
        fi = f if inactive is None else f[inactive]
        return float(fi @ fi)

    def _inactive(self, x, f):
        """PETSc's inactive set, (x > lb + w or f < 0) and (x < ub - w or f > 0), as a mask, or
        None when it is everything because every value lies inside the windows (the common
        case, two reductions instead of seven array operations)."""
        w = VI_BOUND_WINDOW
        if x.min(initial=np.inf) > self.lb + w and x.max(initial=-np.inf) < self.ub - w:
            return None
        return ((x > self.lb + w) | (f < 0.0)) & ((x < self.ub - w) | (f > 0.0))

    def step(self, z0: PETSc.Vec, l: PETSc.Vec, z: PETSc.Vec, atol: float, rtol: float) -> bool:
        """Try the step from z0 (the owned part is read); on success write z (owned part; the
        caller scatters) and return True. On failure z is untouched."""
        B, F = self.B, self.F
        B.mult(z0, F)
        F.axpy(-1.0, l)
        x0, f0 = z0.getArray(readonly=True), self._f
        inactive = self._inactive(x0, f0)
        fnorm0 = float(np.sqrt(self._allsum([self._norm_sq(f0, inactive)])[0]))
        if fnorm0 <= atol:  # the SNES stops at iteration 0: z = z0
            z.array[:] = x0
            self.hits += 1
            self.unchanged += 1
            return True
        all_free = inactive is None or bool(inactive.all())
        if self.comm.size > 1:
            all_free = self.comm.allreduce(all_free, op=MPI.LAND)
        if not all_free and not self.direct_reduced and self._pause > 0:
            self._pause -= 1  # the SNES's own Newton step would be repeated: results unchanged
            self.skipped += 1
            return False
        if not self._solve(inactive, f0, all_free) or not self._accept(x0, l, z, inactive, atol,
                                                                        rtol, fnorm0):
            self.fallbacks += 1
            if not all_free:  # wait 1, 2, 4, ... 16 steps before the next such attempt
                self._failures += 1
                self._pause = min(2 ** (self._failures - 1), MAX_PAUSE)
            return False
        self._failures = 0
        self.hits += 1
        return True

    def _accept(self, x0, l, z, inactive, atol, rtol, fnorm0) -> bool:
        """Step 2's update and projection, step 3's test; z = z1 if it passes."""
        B, F = self.B, self.F
        x1, y = self._x1, self._y
        if inactive is None:  # x1 = x0 - y, the SNES's update (line search "basic")
            np.subtract(x0, y, out=x1)
            free = x1
        else:
            x1[:] = x0
            x1[inactive] -= y[inactive]
            free = x1[inactive]
        low, high = free.min(initial=np.inf), free.max(initial=-np.inf)
        violation = max(self.lb - low, high - self.ub, 0.0)
        if violation > 0.0:  # the SNES's projection onto the bounds
            np.minimum(np.maximum(x1, self.lb, out=x1), self.ub, out=x1)
        B.mult(self.x1, F)
        F.axpy(-1.0, l)
        f1 = self._f
        fn1_sq, violating = self._allsum([self._norm_sq(f1, self._inactive(x1, f1)),
                                          float(violation > FEASIBILITY_TOL)])
        fnorm1 = float(np.sqrt(fn1_sq))
        if violating or not (fnorm1 <= atol or fnorm1 <= rtol * fnorm0):
            return False
        z.array[:] = x1
        return True

    def _solve(self, inactive, f0, all_free) -> bool:
        """The Newton direction: B_II y_I = F0_I into self.y (entries outside I are left)."""
        if all_free:  # empty active set: B itself, its solver built once per run
            if self._full is None:
                self._full = self._ksp(self.B, self.direct_full)
            ksp, y = self._full, self.y
            ksp.solve(self.F, y)  # F holds F0 until _accept
        else:
            if inactive is None:  # empty here, not on another rank
                inactive = np.ones(f0.shape, dtype=bool)
            ksp, rhs, y = self._reduced(inactive)
            rhs.array[:] = f0[inactive]
            ksp.solve(rhs, y)
            self.y.array[inactive] = y.array
        return ksp.getConvergedReason() > 0

    def _reduced(self, inactive):
        """(KSP, rhs, solution) of B_II, rebuilt only when the inactive set changes."""
        same = self._key is not None and np.array_equal(inactive, self._key)
        if self.comm.size > 1:
            same = self.comm.allreduce(bool(same), op=MPI.LAND)
        if not same:
            for obj in self._cached[1:]:  # the KSP is kept
                obj.destroy()
            rows = (self.rstart + np.flatnonzero(inactive)).astype(PETSc.IntType)
            index = PETSc.IS().createGeneral(rows, comm=self.B.getComm())
            Bii = self.B.createSubMatrix(index, index)
            index.destroy()
            y, rhs = Bii.createVecs()
            ksp = self._reduced_ksp
            if ksp is None:
                ksp = self._reduced_ksp = self._ksp(Bii, self.direct_reduced)
            else:  # the same KSP object (type and options kept), new operator
                ksp.reset()
                ksp.setOperators(Bii)
                ksp.setUp()
                self.setups += 1
            self._cached = (ksp, rhs, y, Bii)
            self._key = inactive.copy()
        return self._cached[:3]

    def _ksp(self, A, direct: bool) -> PETSc.KSP:
        ksp = PETSc.KSP().create(self.B.getComm())
        ksp.setOperators(A)
        if direct:  # nested dissection: several times faster solves than the natural order
            ksp.setType("preonly")
            pc = ksp.getPC()
            pc.setType("cholesky")
            pc.setFactorSolverType("petsc" if self.comm.size == 1 else "mumps")
            if self.comm.size == 1:
                pc.setFactorOrdering("nd")
        else:  # the SNES's own Newton step: its KSP options (type, preconditioner, tolerances)
            ksp.setOptionsPrefix(self.snes_ksp.getOptionsPrefix())
            ksp.setFromOptions()
        ksp.setUp()
        self.setups += 1
        return ksp
