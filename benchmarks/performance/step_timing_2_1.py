"""Cost of one Section 2.1 time step at the reference size n = 160 (Example 1), split into
assembly, damage solve and elasticity solve, for two elasticity strategies:

  lagged:  CG + MUMPS factorisation of an earlier matrix, rebuilt when CG needs > 8 iterations
           (the package default: the damage matrix and the elasticity factorisation are reused)
  fresh:   a new MUMPS LU factorisation every step (-mech_ksp_type preonly)

    [mpirun -n 2] .venv/bin/python benchmarks/performance/step_timing_2_1.py [--n 160] [--steps 40]

Writes results/bench/step_timing_2_1.json. The steps are taken from t = 0 with k = 5e-4 (the
reference time step), after one warm-up step (JIT and first factorisations excluded).
"""
import argparse
import json
import time
from pathlib import Path

from mpi4py import MPI
from petsc4py import PETSc

from damage_dolfinx.catalogue import examples
from damage_dolfinx.runtime import io
from damage_dolfinx.models.elastic_2_1 import ElasticDamage

parser = argparse.ArgumentParser()
parser.add_argument("--n", type=int, default=160)
parser.add_argument("--k", type=float, default=5e-4)
parser.add_argument("--steps", type=int, default=40)
parser.add_argument("--out", default="results/bench")
args = parser.parse_args()
comm = MPI.COMM_WORLD
PETSc.Options()["fresh_mech_ksp_type"] = "preonly"
PETSc.Options()["fresh_mech_pc_type"] = "lu"
PETSc.Options()["fresh_mech_pc_factor_mat_solver_type"] = "mumps"
ex = examples.get("2.1-ex1")
results = {}
for label, prefix in (("lagged", "mech_"), ("fresh", "fresh_mech_")):
    stepper = ex.build(comm, n=args.n, k=args.k, T=args.k * (args.steps + 1))
    if prefix != "mech_":  # same data, elasticity solver under another options prefix
        stepper = ElasticDamage(stepper.data, mech_prefix=prefix, damage_prefix="fresh_damage_")
    stepper.initialize()
    stepper.advance()  # warm-up
    mech, dmg = stepper.mech, stepper.damage.linear
    base_m, base_d = dict(mech.timings), dict(dmg.timings)
    its0, fac0 = mech.iterations, mech.factorizations
    comm.Barrier()
    start = time.perf_counter()
    for _ in range(args.steps):
        stepper.advance()
    comm.Barrier()
    per_step = (time.perf_counter() - start) / args.steps
    split = {f"mech_{k}": (mech.timings[k] - base_m.get(k, 0.0)) / args.steps for k in mech.timings}
    split.update({f"damage_{k}": (dmg.timings[k] - base_d.get(k, 0.0)) / args.steps
                  for k in dmg.timings})
    results[label] = {"seconds_per_step": per_step, "split_seconds_per_step": split,
                      "mech_ksp_its_per_step": (mech.iterations - its0) / args.steps,
                      "mech_factorizations": mech.factorizations - fac0,
                      "min_zeta": stepper.zeta_min()}
summary = {"example": "2.1-ex1", "n": args.n, "k": args.k, "steps_timed": args.steps,
           "dofs_u": stepper.mesh_info()["dofs_u"], "dofs_zeta": stepper.mesh_info()["dofs_zeta"],
           "mpi_size": comm.size, "results": results, "environment": io.environment(comm)}
if comm.rank == 0:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "step_timing_2_1.json").write_text(json.dumps(summary, indent=2))
    print(f"Section 2.1 Example 1, n = {args.n} ({summary['dofs_u']} displacement dofs), "
          f"k = {args.k}, {comm.size} rank(s), mean over {args.steps} steps:")
    for label, r in results.items():
        print(f"  {label:7s} {1e3 * r['seconds_per_step']:7.1f} ms/step  "
              f"(CG its/step {r['mech_ksp_its_per_step']:.1f}, factorisations "
              f"{r['mech_factorizations']})")
        for key, value in sorted(r["split_seconds_per_step"].items()):
            print(f"           {key:24s} {1e3 * value:7.1f} ms")
