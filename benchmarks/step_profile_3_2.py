"""Per-step cost of Section 3.2 Example 1 (issue 18): the steps measured by performance.py
(steps 2-10 at the example's k = 0.01, the stick-slip start), split into the damage step and the
friction step, with wall and CPU time (CPU time is robust to other jobs on the machine).

    .venv/bin/python benchmarks/step_profile_3_2.py --n 128 --label after
    PYTHONPATH=/path/to/old/checkout .venv/bin/python benchmarks/step_profile_3_2.py --label before
    .venv/bin/python benchmarks/step_profile_3_2.py --compare before after

Each run writes <out>/<label>.json and the fields at the last step to <out>/<label>.npz;
--compare prints (and writes compare.json) the per-step numbers side by side and the largest
relative field difference. Serial.
"""
import argparse
import json
import time
from pathlib import Path

import numpy as np

parser = argparse.ArgumentParser()
parser.add_argument("--n", type=int, default=128)
parser.add_argument("--k", type=float, default=0.01)
parser.add_argument("--steps", type=int, default=10)
parser.add_argument("--label", default="after")
parser.add_argument("--compare", nargs=2, metavar=("BEFORE", "AFTER"))
parser.add_argument("--out", default="benchmarks/reference_output/step_profile_3_2")
args = parser.parse_args()
out = Path(args.out)
out.mkdir(parents=True, exist_ok=True)


def profile():
    from mpi4py import MPI

    import damage_dolfinx
    from damage_dolfinx.catalogue import examples
    s = examples.get("3.2-ex1").build(MPI.COMM_WORLD, n=args.n, k=args.k,
                                      T=args.k * args.steps)
    s.initialize()
    rows = []
    for n in range(1, args.steps + 1):
        t0, c0, tim = time.perf_counter(), time.process_time(), dict(s.timings)
        its = s.advance()
        rows.append({"step": n, "wall_ms": 1e3 * (time.perf_counter() - t0),
                     "cpu_ms": 1e3 * (time.process_time() - c0),
                     "damage_ms": 1e3 * (s.timings["damage"] - tim["damage"]),
                     "friction_ms": 1e3 * (s.timings["friction"] - tim["friction"]),
                     "friction_its": its["friction_its"], "damage_its": its["damage_its"]})
    later = rows[1:]  # steps 2.., as performance.py
    mean = {key: float(np.mean([r[key] for r in later]))
            for key in ("wall_ms", "cpu_ms", "damage_ms", "friction_ms", "friction_its")}
    result = {"label": args.label, "n": args.n, "k": args.k, "steps": args.steps,
              "dofs_u": s.u.function_space.dofmap.index_map.size_global * 2,
              "code": str(Path(damage_dolfinx.__file__).parent.parent),
              "load_average": [round(x, 2) for x in __import__("os").getloadavg()],
              "mean_steps_2_on": mean, "steps": rows,
              "iterations": s.iteration_totals()}
    solver = getattr(getattr(s.friction, "pdas", None), "solver", None)
    if solver is not None and hasattr(solver, "condensed_solves"):
        result["diagonal_update_solver"] = {
            key: getattr(solver, key) for key in ("size_C", "full_factorizations",
                                                  "condensed_factorizations", "full_solves",
                                                  "condensed_solves")}
    (out / f"{args.label}.json").write_text(json.dumps(result, indent=1))
    np.savez(out / f"{args.label}.npz", u=s.u.x.array, v=s.v.x.array, zeta=s.zeta.x.array)
    print(json.dumps({k: v for k, v in result.items() if k != "steps"}, indent=1))


def compare(before, after):
    b, a = (json.loads((out / f"{x}.json").read_text()) for x in (before, after))
    fb, fa = (np.load(out / f"{x}.npz") for x in (before, after))
    diff = {key: float(np.abs(fb[key] - fa[key]).max() / max(np.abs(fb[key]).max(), 1e-300))
            for key in ("u", "v", "zeta")}
    table = {key: [round(b["mean_steps_2_on"][key], 2), round(a["mean_steps_2_on"][key], 2)]
             for key in b["mean_steps_2_on"]}
    result = {"before": before, "after": after, "n": a["n"], "k": a["k"],
              "mean_steps_2_on_before_after": table, "field_difference_relative": diff}
    (out / "compare.json").write_text(json.dumps(result, indent=1))
    print(json.dumps(result, indent=1))


if args.compare:
    compare(*args.compare)
else:
    profile()
