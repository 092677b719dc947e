"""What a run checks as it goes: progress lines on rank 0, the state after every step (finite,
zeta within its bounds), and solver exceptions turned into one-line ConvergenceErrors."""
from __future__ import annotations

import math
import time

import numpy as np

from damage_dolfinx.numerics.solvers import ConvergenceError
from damage_dolfinx.core.parameters import InputError


class Progress:
    """Rank-0 progress lines, at most one every ``interval`` seconds (plus first and last)."""

    def __init__(self, label, total, comm, enabled=True, interval=2.0):
        self.label, self.total, self.enabled = label, total, enabled and comm.rank == 0
        self.interval, self.start, self.last = interval, time.perf_counter(), -math.inf

    def __call__(self, step, t, stats, scalars, force=False):
        """``scalars``: the step's scalars, or a callable returning them (asked only when a line
        is printed)."""
        now = time.perf_counter()
        if not self.enabled or (not force and now - self.last < self.interval and step != self.total):
            return
        self.last = now
        if callable(scalars):
            scalars = scalars()
        elapsed = now - self.start
        eta = elapsed / max(step, 1) * (self.total - step)
        its = " ".join(f"{k}={v}" for k, v in stats.items())
        print(f"[{self.label}] step {step}/{self.total} t={t:.5g} {its} "
              f"min zeta={scalars['zeta_min']:.4f} ({elapsed:.1f} s, ETA {eta:.0f} s)", flush=True)


#: zeta may leave [zeta_star, 1] by this much (solver tolerance) before the run is stopped,
#: where the damage step imposes the bounds (the obstacle step of most models)
STATE_TOLERANCE = 1e-6
#: the same for a damage step in PDE form (2.1, 2.3: the scheme imposes no bound, zeta may
#: overshoot 1 by discretisation, e.g. 3.7e-6 for 2.1-ex1 at n = 10, and the step that reaches
#: zeta_star, which ends the run by design, may pass far below it: -1.9 for 2.1-ex1 with
#: lam_u_plus = 1e8, -1.25 for the literal reading of the arch): only a departure of a hundred
#: times the whole range is absurd
PDE_STATE_MARGIN = 100.0


#: exceptions a solver step can raise besides ConvergenceError (PETSc errors, our own
#: factorisations' RuntimeError, arithmetic on broken numbers)
SOLVER_EXCEPTIONS = (RuntimeError, ArithmeticError, ValueError, np.linalg.LinAlgError)


def solver_step(fn, where):
    """``fn()``, any solver exception turned into one-line ConvergenceError naming ``where``."""
    from petsc4py import PETSc
    try:
        return fn()
    except (ConvergenceError, InputError):
        raise
    except (PETSc.Error, *SOLVER_EXCEPTIONS) as exc:
        text = next((line.strip() for line in reversed(str(exc).splitlines())
                     if line.strip() and "() at " not in line), type(exc).__name__)
        raise ConvergenceError(f"{where}: {type(exc).__name__}: {text.lstrip('[0123456789] ')}"
                               ) from exc


def state_views(stepper) -> list:
    """(name, owned values) of every Function the model holds as state (models/contracts.py
    ``state_functions``: u, zeta, what it checkpoints, both sides of ``old_state``, ``update``,
    its output fields), looked up once (the value arrays are views that stay valid)."""
    views = getattr(stepper, "_state_views", None)
    if views is None:
        from damage_dolfinx.models.contracts import state_functions
        views = []
        bounds = {id(getattr(stepper, name, None)): (name, lo, hi)
                  for name, (lo, hi) in (getattr(stepper, "state_bounds", None) or {}).items()}
        for name, f in state_functions(stepper):
            V = f.function_space
            is_zeta = f is getattr(stepper, "zeta", None)
            views.append((name, f.x.array[:V.dofmap.index_map.size_local
                                          * V.dofmap.index_map_bs],
                          True if is_zeta else bounds.get(id(f), False)))
        try:
            stepper._state_views = views
        except AttributeError:  # a stepper without a __dict__: looked up each time
            pass
    return views


def state_problem(stepper, tolerance=None):
    """What is wrong with the stepper's owned values (NaN/Inf in any Function it holds as
    state, :func:`state_views`; zeta outside [zeta_star - tol, 1 + tol]; tol STATE_TOLERANCE,
    or PDE_STATE_MARGIN for a damage step in PDE form) on this rank, as (code, detail): code 0
    (fine), 1 (non-finite), 2 (zeta out of range). Owned arrays, NumPy only."""
    zeta_star = stepper.params.zeta_star
    if tolerance is None:
        bounded = getattr(getattr(stepper, "damage", None), "obstacle", True)
        tolerance = STATE_TOLERANCE if bounded else PDE_STATE_MARGIN
    for name, values, bounded in state_views(stepper):
        if bounded and values.size:  # min and max propagate a NaN: no third pass
            lo, hi = float(values.min()), float(values.max())
            if not (np.isfinite(lo) and np.isfinite(hi)):
                return 1, f"{name} is not finite (NaN or Inf)"
            if bounded is not True:  # a field of the model's own with its state_bounds
                _, low, high = bounded
                if lo < low - STATE_TOLERANCE or hi > high + STATE_TOLERANCE:
                    return 2, (f"{name} left its bounds [{low:g}, {high:g}] (state_bounds) by "
                               f"more than {STATE_TOLERANCE:g}: min {lo:.6g}, max {hi:.10g}")
            elif lo < zeta_star - tolerance or hi > 1.0 + tolerance:
                return 2, (f"zeta left [zeta_star, 1] = [{zeta_star:g}, 1] by more than "
                           f"{tolerance:g}: min {lo:.6g}, max {hi:.10g}")
        elif values.size and not np.isfinite(values).all():
            return 1, f"{name} is not finite (NaN or Inf)"
    return 0, ""
