"""Time per step of every problem against its floor at the same size.

    .venv/bin/python benchmarks/performance/step_floor.py                    # ~4k dofs (n = 45), serial
    .venv/bin/python benchmarks/performance/step_floor.py --n 128 --only 3.2-ex1

Each problem is built at --n (the wrench 3.3-ex3 at its thesis mesh h = 0.15, 1960 dofs) with
the example's own k, advanced --warmup steps, then --steps steps are timed (wall and CPU; the
stepper's own split, e.g. damage / velocity / friction, from its ``timings``). The floor is
measured on the vector P1 matrix rho M + K_eps of the same mesh (the shape of every
mechanical operator here): one sparse matrix-vector product (SpMV), one CG + Jacobi
iteration, and one pair of triangular solves with its Cholesky factor (the solver the
factorised schemes use), each the fastest of 5 blocks. The damage step (DamageStep.solve:
right-hand side and solve) is timed on its own (split "damage_step"), with the obstacle fast
path's hits and SNES fallbacks (damage_dolfinx/obstacle.py).

The floor of the issue is ONE solve per step; the schemes need several (a staggered damage and
mechanical solve, Newton iterations, CG iterations with a lagged factor). So PETSc's own event
log also counts, per step, the triangular-solve pairs (MatSolve), the SpMVs (MatMult,
MatMultTranspose) and the factorisations, and times PETSc's numerical kernels (the leaf events
KERNEL_EVENTS: SpMV, triangular solves, factorisations, vector operations): "step over its
solves" = step / (MatSolve per step x one Cholesky solve), "step over its kernels" = step /
that kernel time, i.e. how far the step is above the arithmetic its own scheme performs.
Serial. Writes
benchmarks/reference_output/step_floor/step_floor_n<N>_<date>.json and .md (--out to change; the
report shows the newest date of each size).
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

from damage_dolfinx import compat
from damage_dolfinx.catalogue import examples
from damage_dolfinx.forms.constitutive import eps

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from common import best, profile_rows, write_record  # noqa: E402

#: PETSc leaf events (no nesting among them): the arithmetic of a step
KERNEL_EVENTS = ["MatMult", "MatMultAdd", "MatMultTranspose", "MatSolve", "MatCholFctrSym",
                 "MatCholFctrNum", "MatLUFactorSym", "MatLUFactorNum", "MatGetOrdering",
                 "VecDot", "VecTDot", "VecMDot", "VecNorm", "VecScale", "VecCopy", "VecSet",
                 "VecAXPY", "VecAYPX", "VecAXPBYCZ", "VecWAXPY", "VecMAXPY",
                 "VecPointwiseMult", "VecReciprocal"]
PETSc.Log.begin()

PROBLEMS = ["2.1-ex1", "2.2-ex1", "2.3-ex1", "2.4-ex1", "3.1-ex1", "3.2-ex1", "3.3-ex1",
            "3.3-ex3"]

parser = argparse.ArgumentParser()
parser.add_argument("--n", type=int, default=45, help="cells per side (45: about 4k dofs)")
parser.add_argument("--steps", type=int, default=20)
parser.add_argument("--warmup", type=int, default=2)
parser.add_argument("--only", nargs="+")
parser.add_argument("--out", default="benchmarks/reference_output/step_floor")
parser.add_argument("--label", default=time.strftime("%Y-%m-%d"),
                    help="suffix of the output files (default: the date, YYYY-MM-DD)")
args = parser.parse_args()
comm = MPI.COMM_WORLD
if comm.size != 1:
    raise SystemExit("step_floor.py is a serial profile")


def floors(V) -> dict:
    """Microseconds: SpMV, one CG + Jacobi iteration and one Cholesky solve with M + K_eps."""
    du, w = ufl.TrialFunction(V), ufl.TestFunction(V)
    a = compat.form(ufl.inner(du, w) * ufl.dx + ufl.inner(eps(du), eps(w)) * ufl.dx)
    A = compat.create_matrix(a)
    compat.assemble_matrix(A, a, [])
    A.assemble()
    x, y = A.createVecRight(), A.createVecLeft()
    x.setRandom()
    repeat = max(10, int(2e6 / A.getSize()[0]))
    out = {"dofs": A.getSize()[0], "spmv_us": 1e6 * best(lambda: A.mult(x, y), repeat)}
    ksp = PETSc.KSP().create(comm)
    ksp.setOperators(A)
    ksp.setType("cg")
    ksp.getPC().setType("jacobi")
    ksp.setTolerances(rtol=1e-300, atol=1e-300, max_it=50)
    ksp.setConvergenceTest(lambda *a: 0)  # exactly max_it iterations
    ksp.setErrorIfNotConverged(False)
    ksp.setUp()
    out["cg_iteration_us"] = 1e6 * best(lambda: ksp.solve(y, x), 1) / 50
    chol = PETSc.KSP().create(comm)
    chol.setOperators(A)
    chol.setType("preonly")
    chol.getPC().setType("cholesky")
    chol.setUp()
    out["cholesky_solve_us"] = 1e6 * best(lambda: chol.solve(y, x), max(3, repeat // 10))
    return out


def petsc_events() -> dict:
    """Cumulative (count, seconds) of KERNEL_EVENTS."""
    out = {}
    for name in KERNEL_EVENTS:
        info = PETSc.Log.Event(name).getPerfInfo()
        out[name] = (info["count"], info["time"])
    return out


def _timed(solve, clock):
    def wrapper():
        start = time.perf_counter()
        out = solve()
        clock[0] += time.perf_counter() - start
        return out
    return wrapper


def profile(example) -> dict:
    ex = examples.get(example)
    size = {"h": 0.15} if example == "3.3-ex3" else {"n": args.n}
    k = ex.k
    T = k * (args.warmup + args.steps)
    overrides = {"stability_check": "off"} if "stability_check" in ex.params.extra else None
    s = ex.build(comm, k=k, T=T, overrides=overrides, **size)
    s.initialize()
    for _ in range(args.warmup):
        s.advance()
    timings0 = dict(getattr(s, "timings", {}))
    damage, damage_clock = getattr(s, "damage", None), [0.0]
    if damage is not None:  # the damage step timed on its own (right-hand side + solve)
        damage.solve = _timed(damage.solve, damage_clock)
    counts0 = damage.counts() if hasattr(damage, "counts") else {}
    events0 = petsc_events()
    wall0, cpu0 = time.perf_counter(), time.process_time()
    for _ in range(args.steps):
        s.advance()
        s.scalars()  # what the runner asks after every step (history.csv)
    wall = (time.perf_counter() - wall0) / args.steps
    cpu = (time.process_time() - cpu0) / args.steps
    events = {name: ((c - events0[name][0]) / args.steps, (t - events0[name][1]) / args.steps)
              for name, (c, t) in petsc_events().items()}
    per_step = lambda *names: sum(events[n][0] for n in names)  # noqa: E731
    kernel_s = sum(t for _, t in events.values())
    split = {key: 1e3 * (value - timings0.get(key, 0.0)) / args.steps
             for key, value in getattr(s, "timings", {}).items()
             if isinstance(value, float) and key != "stability"}
    if damage is not None:
        split["damage_step"] = 1e3 * damage_clock[0] / args.steps
    counts = {key.replace("damage_vi_fast_", ""): value - counts0[key]
              for key, value in (damage.counts() if counts0 else {}).items()}
    floor = floors(s.u.function_space)
    step_us = 1e6 * wall
    return {"example": example, **size, "k": k, "dofs_u": floor["dofs"],
            "wall_ms_per_step": 1e3 * wall, "cpu_ms_per_step": 1e3 * cpu,
            "split_ms_per_step": {key: round(v, 4) for key, v in split.items()},
            "damage_fast_path": counts,
            "floor_us": {key: round(v, 2) for key, v in floor.items() if key != "dofs"},
            "step_over_spmv": step_us / floor["spmv_us"],
            "step_over_cg_iteration": step_us / floor["cg_iteration_us"],
            "step_over_cholesky_solve": step_us / floor["cholesky_solve_us"],
            "per_step": {"solves": per_step("MatSolve"),
                         "spmv": per_step("MatMult", "MatMultAdd", "MatMultTranspose"),
                         "factorisations": per_step("MatCholFctrNum", "MatLUFactorNum"),
                         "kernel_ms": 1e3 * kernel_s},
            "step_over_its_solves": step_us / max(per_step("MatSolve"), 1.0)
            / floor["cholesky_solve_us"],
            "step_over_its_kernels": wall / kernel_s if kernel_s > 0 else float("nan")}


rows = profile_rows(PROBLEMS, args.only, profile)
stem = f"step_floor_n{args.n}_{args.label}"
lines = ["| example | dofs (u) | ms per step (wall / CPU) | split (ms) | SpMV / CG it / Cholesky "
         "solve (us) | step over SpMV / CG it / Cholesky solve | damage fast path: hits "
         "(unchanged) / SNES fallbacks | per step: solves / SpMVs / factorisations / PETSc "
         "kernels (ms) | step over its solves / its kernels |",
         "|---|---|---|---|---|---|---|---|---|"]
for r in rows:
    f = r["floor_us"]
    split = ", ".join(f"{k} {v:.2f}" for k, v in r["split_ms_per_step"].items())
    c, q = r["damage_fast_path"], r["per_step"]
    fast = f"{c['hits']} ({c['unchanged']}) / {c['fallbacks']}" if c else "-"
    lines.append(f"| {r['example']} | {r['dofs_u']} | {r['wall_ms_per_step']:.2f} / "
                 f"{r['cpu_ms_per_step']:.2f} | {split} | {f['spmv_us']:.0f} / "
                 f"{f['cg_iteration_us']:.0f} / {f['cholesky_solve_us']:.0f} | "
                 f"{r['step_over_spmv']:.0f} / {r['step_over_cg_iteration']:.0f} / "
                 f"{r['step_over_cholesky_solve']:.1f} | {fast} | {q['solves']:.1f} / "
                 f"{q['spmv']:.1f} / {q['factorisations']:.2f} / {q['kernel_ms']:.2f} | "
                 f"{r['step_over_its_solves']:.1f} / {r['step_over_its_kernels']:.1f} |")
write_record(args.out, stem, rows, lines)
