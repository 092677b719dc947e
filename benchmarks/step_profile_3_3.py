"""Per-step profile of the Section 3.3 explicit-dynamics loop (issue 18), before and after the
per-step changes, measured in ONE process so that the ratios hold on a loaded machine.

    .venv/bin/python benchmarks/step_profile_3_3.py                                # wrench, h = 0.15
    .venv/bin/python benchmarks/step_profile_3_3.py --example 3.3-ex1 --n 128 --k 0.001 --steps 10

Two steppers of the same run are built: "before" (the velocity matrix re-assembled each step,
right-hand side assembled, CG started from v_{n-1}: FAST_MATRIX = FAST_RHS =
VELOCITY_EXTRAPOLATION = False) and "after" (the defaults). They
advance in alternating blocks of --block steps (each its own state, the same trajectory), after
--warmup steps each. Each step is split into: the damage step (right-hand side assembly and
bookkeeping / SNES), the velocity step (matrix, right-hand side, CG with
its iteration count), the remaining Python/NumPy bookkeeping of _advance, and what the runner
asks of the stepper after every step for history.csv and summary.json (scalars(),
summary_extra(), iteration_totals()). The runner's own CSV/JSON writing is not included.
Floors at the same size: one SpMV with the velocity matrix, one CG + Jacobi iteration on it
(fixed 200 iterations, averaged), one SpMV with the damage matrix. Serial. Writes
benchmarks/reference_output/step_profile_3_3/<example>_<size>.json (--out to change).
"""
import argparse
import json
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from damage_dolfinx import compat
from damage_dolfinx.catalogue import examples
from damage_dolfinx.models import fully_damageable_3_3 as fd

sys.path.insert(0, str(Path(__file__).resolve().parent))
from timing import best  # noqa: E402

parser = argparse.ArgumentParser()
parser.add_argument("--example", default="3.3-ex3")
parser.add_argument("--h", type=float, help="gmsh element size (wrench: 0.15, the thesis size)")
parser.add_argument("--n", type=int, help="cells per side (3.3-ex1, 3.3-ex2)")
parser.add_argument("--k", type=float, help="time step (default: the example's)")
parser.add_argument("--steps", type=int, default=600, help="timed steps per configuration")
parser.add_argument("--block", type=int, default=50, help="steps per alternating block")
parser.add_argument("--warmup", type=int, default=20)
parser.add_argument("--out", default="benchmarks/reference_output/step_profile_3_3")
args = parser.parse_args()
comm = MPI.COMM_WORLD
if comm.size != 1:
    raise SystemExit("step_profile_3_3.py is a serial profile")
if args.example == "3.3-ex3" and args.h is None and args.n is None:
    args.h = 0.15


def build(fast: bool):
    fd.FAST_MATRIX = fd.FAST_RHS = fd.VELOCITY_EXTRAPOLATION = fast
    ex = examples.get(args.example)
    k = args.k or ex.k
    s = ex.build(comm, n=args.n, h=args.h, k=k, T=k * (args.warmup + args.steps + 1))
    s.initialize()
    return s


class Profiled:
    """A stepper with timers around the pieces of one step."""

    def __init__(self, stepper):
        self.s, self.t = stepper, defaultdict(float)
        self.steps = 0
        d = stepper.damage
        if d is not None:
            self._wrap(d.snes, "solve", "damage SNES")
        self.mech_its = 0

    def _wrap(self, obj, name, key):
        fn = getattr(obj, name)

        def timed(*a, **kw):
            start = time.perf_counter()
            out = fn(*a, **kw)
            self.t[key] += time.perf_counter() - start
            return out
        setattr(obj, name, timed)

    def advance(self, n, record=True):
        s, m = self.s, self.s.mech
        for _ in range(n):
            before = {**s.timings}, {**m.timings}, m.iterations
            start = time.perf_counter()
            s.advance()
            mid = time.perf_counter()
            if record:
                s.scalars(), s.summary_extra(), s.iteration_totals()
            end = time.perf_counter()
            if not record:
                continue
            self.steps += 1
            self.t["step (advance)"] += mid - start
            self.t["history/summary (scalars, summary_extra)"] += end - mid
            self.t["damage total"] += s.timings["damage"] - before[0]["damage"]
            for key in ("assemble_matrix", "assemble_rhs", "solve"):
                self.t["velocity " + key] += m.timings[key] - before[1][key]
            self.t["velocity total"] += s.timings["velocity"] - before[0]["velocity"]
            self.mech_its += m.iterations - before[2]

    def split(self) -> dict:
        t, n = self.t, max(self.steps, 1)
        ms = {key: 1e3 * value / n for key, value in t.items()}
        ms["damage rhs + bookkeeping"] = ms["damage total"] - ms.get("damage SNES", 0.0)
        ms["velocity bookkeeping"] = ms["velocity total"] - sum(
            ms["velocity " + key] for key in ("assemble_matrix", "assemble_rhs", "solve"))
        ms["advance bookkeeping (copies, u update, profiles)"] = ms["step (advance)"] - \
            ms["damage total"] - ms["velocity total"]
        ms["step + history"] = ms["step (advance)"] + ms["history/summary (scalars, summary_extra)"]
        out = {"ms_per_step": {k: round(v, 4) for k, v in sorted(ms.items())},
               "cg_iterations_per_step": self.mech_its / n}
        d = self.s.damage
        if d is not None:
            out["damage_snes_iterations"] = d.iterations
        return out


def floors(stepper, repeat=200) -> dict:
    """Microseconds (fastest of 5 blocks): SpMV and one CG + Jacobi iteration with the velocity
    matrix; SpMV with the damage matrix."""
    A = stepper.mech.A
    x, y = A.createVecRight(), A.createVecLeft()
    x.setRandom()
    spmv = best(lambda: A.mult(x, y), repeat)
    ksp = PETSc.KSP().create(comm)
    ksp.setOperators(A)
    ksp.setType("cg")
    ksp.getPC().setType("jacobi")
    ksp.setTolerances(rtol=1e-300, atol=1e-300, max_it=repeat)
    ksp.setConvergenceTest(lambda *a: 0)  # never converged: exactly max_it iterations
    ksp.setErrorIfNotConverged(False)
    ksp.setUp()
    cg = best(lambda: ksp.solve(y, x), 1) / max(ksp.getIterationNumber(), 1)
    out = {"velocity_dofs": A.getSize()[0], "velocity_nnz": int(A.getInfo()["nz_used"]),
           "spmv_us": 1e6 * spmv, "cg_iteration_us": 1e6 * cg}
    fast = getattr(stepper.mech, "fast", None)
    if fast is not None:  # the sparse map when zeta HAS changed (the wrench keeps zeta = 1 early)
        start = time.perf_counter()
        for _ in range(20):
            fast.forget()
            fast.update(stepper.zeta.x.array)
        out["matrix_map_update_us"] = 1e6 * (time.perf_counter() - start) / 20
        R = compat.create_matrix(stepper.mech.a)
        start = time.perf_counter()
        for _ in range(5):
            R.zeroEntries()
            compat.assemble_matrix(R, stepper.mech.a, stepper.mech.bcs)
            R.assemble()
        out["matrix_reassembly_us"] = 1e6 * (time.perf_counter() - start) / 5
    if stepper.damage is not None:
        B = stepper.damage.A
        x, y = B.createVecRight(), B.createVecLeft()
        out.update(damage_dofs=B.getSize()[0],
                   damage_spmv_us=1e6 * best(lambda: B.mult(x, y), repeat))
    return out


runs = {"before": Profiled(build(False)), "after": Profiled(build(True))}
fast = runs["after"].s.mech
for p in runs.values():
    p.advance(args.warmup, record=False)
done = 0
while done < args.steps:
    n = min(args.block, args.steps - done)
    for p in runs.values():
        p.advance(n)
    done += n
result = {"example": args.example, "h": args.h, "n": args.n, "k": runs["after"].s.k,
          "steps_timed": args.steps, "t_reached": runs["after"].s.t,
          "load_average": list(np.round(__import__("os").getloadavg(), 2)),
          "floor": floors(runs["after"].s),
          "fast_matrix": {"colours": fast.fast.colours, "P_nnz": int(fast.fast.P.nnz)}
          if hasattr(fast, "fast") else None}
for name, p in runs.items():
    result[name] = p.split()
b, a = (result[k]["ms_per_step"] for k in ("before", "after"))
result["speedup"] = {k: round(b[k] / a[k], 2) for k in b if a.get(k, 0) > 1e-6}
# the two runs follow the same trajectory: their states agree to solver tolerance
s0, s1 = runs["before"].s, runs["after"].s
result["state_difference"] = {
    f.name: float(np.abs(f.x.array - g.x.array).max() / max(np.abs(f.x.array).max(), 1e-300))
    for f, g in ((s0.u, s1.u), (s0.v, s1.v), (s0.zeta, s1.zeta))}
floor_us = result["floor"]
result["over_floor"] = {name: {
    "step_over_cg_iteration": round(1e3 * r["ms_per_step"]["step + history"]
                                    / floor_us["cg_iteration_us"], 1),
    "step_over_spmv": round(1e3 * r["ms_per_step"]["step + history"] / floor_us["spmv_us"], 1),
    "cg_over_cg_floor": round(1e3 * r["ms_per_step"]["velocity solve"]
                              / (floor_us["cg_iteration_us"] * max(r["cg_iterations_per_step"], 1)), 2)}
    for name, r in ((n, result[n]) for n in ("before", "after"))}

print(f"{args.example} (h={args.h}, n={args.n}), k = {result['k']:.4g}, {args.steps} steps per "
      f"configuration, load average {result['load_average']}")
print(f"floor: {floor_us['velocity_dofs']} dofs, SpMV {floor_us['spmv_us']:.1f} us, one CG "
      f"iteration {floor_us['cg_iteration_us']:.1f} us, damage SpMV "
      f"{floor_us.get('damage_spmv_us', float('nan')):.1f} us")
if "matrix_map_update_us" in floor_us:
    print(f"velocity matrix with a changed zeta: sparse map {floor_us['matrix_map_update_us']:.0f} "
          f"us, re-assembly {floor_us['matrix_reassembly_us']:.0f} us")
print(f"{'ms per step':52s} {'before':>9s} {'after':>9s} {'ratio':>7s}")
for key in sorted(set(b) | set(a)):
    print(f"{key:52s} {b.get(key, 0):9.4f} {a.get(key, 0):9.4f} "
          f"{result['speedup'].get(key, float('nan')):7.2f}")
for name in ("before", "after"):
    r = result[name]
    print(f"{name}: CG iterations/step {r['cg_iterations_per_step']:.2f}, "
          f"over floor {result['over_floor'][name]}")
print("state difference after vs before (max rel):", result["state_difference"])
size = f"h{args.h}" if args.h else f"n{args.n}"
out = Path(args.out)
out.mkdir(parents=True, exist_ok=True)
(out / f"{args.example}_{size}.json").write_text(json.dumps(result, indent=1))
print("wrote", out / f"{args.example}_{size}.json")
