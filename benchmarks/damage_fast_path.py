"""The damage obstacle step with its fast path (damage_dolfinx/obstacle.py) against SNES
vinewtonrsls alone, on the same states (issue 18).

    .venv/bin/python benchmarks/damage_fast_path.py                  # ~4k dofs (n = 45)
    .venv/bin/python benchmarks/damage_fast_path.py --n 255          # ~131k dofs
    .venv/bin/python benchmarks/damage_fast_path.py --only 3.3-ex3 --checkpoint RUN/checkpoint.npz

Each problem is built twice at --n (the wrench 3.3-ex3 at its thesis mesh h = 0.15) with the
example's own k. Both copies advance --warmup steps with the fast path (identical states), or
both start from --checkpoint (the restart path of the runner). Then copy B switches to the SNES
alone (``damage.fast = None``, what ``-damage_vi_fast 0`` gives) and the two copies advance
--steps steps alternately, step by step, so machine load hits both alike. Reported per problem:
ms per damage step (DamageStep.solve: right-hand side assembly + obstacle solve; mean and, robust
to the preemptions of a loaded machine, median) for each copy,
the fast path's counts, the SNES iterations of each copy, and the largest relative difference
(max norm) of every state field after the steps. Serial. Writes
benchmarks/reference_output/step_floor/damage_fast_path_n<N>[_<label>].json and .md.
"""
import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from damage_dolfinx.runtime import checkpoint
from damage_dolfinx.catalogue import examples

sys.path.insert(0, str(Path(__file__).resolve().parent))
from timing import profile_rows, write_record  # noqa: E402

PROBLEMS = ["2.2-ex1", "2.4-ex1", "3.1-ex1", "3.1-ex2", "3.2-ex1", "3.3-ex1", "3.3-ex3"]

parser = argparse.ArgumentParser()
parser.add_argument("--n", type=int, default=45, help="cells per side (45: about 4k dofs)")
parser.add_argument("--steps", type=int, default=20)
parser.add_argument("--warmup", type=int, default=2)
parser.add_argument("--only", nargs="+")
parser.add_argument("--checkpoint", help="start both copies from this checkpoint.npz")
parser.add_argument("--out", default="benchmarks/reference_output/step_floor")
parser.add_argument("--label", default="")
args = parser.parse_args()
comm = MPI.COMM_WORLD
if comm.size != 1:
    raise SystemExit("damage_fast_path.py is a serial profile")


def timed(step, clock):
    solve = step.solve

    def wrapper():
        start = time.perf_counter()
        out = solve()
        clock.append(time.perf_counter() - start)
        return out
    return wrapper


def build(example):
    ex = examples.get(example)
    size = {"h": 0.15} if example == "3.3-ex3" else {"n": args.n}
    overrides = {"stability_check": "off"} if "stability_check" in ex.params.extra else None
    start, k = 0, ex.k
    if args.checkpoint:  # its step and time step (the wrench: 0.8 k_max, not the catalogue's)
        meta = json.loads(str(np.load(args.checkpoint)["__meta__"]))
        start, k = meta["step"], meta["k"]
    s = ex.build(comm, k=k, T=k * (start + args.warmup + args.steps + 1), overrides=overrides,
                 **size)
    s.initialize()
    if args.checkpoint:
        saved = np.load(args.checkpoint).files  # an older checkpoint may lack monitor arrays
        checkpoint.load(args.checkpoint, {name: f for name, f in s.checkpoint_state().items()
                                          if name in saved})
        s.restore(start)
    for _ in range(args.warmup):
        s.advance()
    return s, size


def profile(example) -> dict:
    (a, size), (b, _) = build(example), build(example)
    b.damage.fast = None  # the SNES alone, as -damage_vi_fast 0
    clocks = {"fast": [], "snes": []}
    a.damage.solve, b.damage.solve = timed(a.damage, clocks["fast"]), timed(b.damage, clocks["snes"])
    counts0, its0 = a.damage.counts(), (a.damage.iterations, b.damage.iterations)
    for _ in range(args.steps):
        a.advance()
        b.advance()
    counts = {key: value - counts0[key] for key, value in a.damage.counts().items()}
    diffs = {}
    for name, fa in a.checkpoint_state().items():
        fb = b.checkpoint_state()[name]
        xa, xb = (fa, fb) if isinstance(fa, np.ndarray) else (fa.x.array, fb.x.array)
        diffs[name] = float(np.abs(xa - xb).max() / max(np.abs(xb).max(), 1e-300))
    zeta = a.zeta.x.array
    return {"example": example, **size, "k": a.data.time.k, "t_start": a.t - args.steps * a.data.time.k,
            "dofs_zeta": int(zeta.size),
            "damage_ms_per_step": {key: 1e3 * float(np.mean(c)) for key, c in clocks.items()},
            "damage_ms_median": {key: 1e3 * float(np.median(c)) for key, c in clocks.items()},
            "fast_path_counts": counts,
            "snes_iterations": {"fast": a.damage.iterations - its0[0], "snes": b.damage.iterations - its0[1]},
            "nodes_at_zeta_star": int(np.sum(zeta <= a.params.zeta_star)),
            "nodes_at_1": int(np.sum(zeta >= 1.0)), "max_relative_difference": diffs}


rows = profile_rows(PROBLEMS, args.only, profile)
stem = f"damage_fast_path_n{args.n}" + (f"_{args.label}" if args.label else "")
lines = ["| example | zeta dofs | t at start | damage ms per step (mean; median), SNES alone -> fast path | "
         "hits (unchanged) / fallbacks / set-ups | SNES its | nodes at zeta* / at 1 | "
         "largest relative field difference |", "|---|---|---|---|---|---|---|---|"]
for r in rows:
    c, ms, its = r["fast_path_counts"], r["damage_ms_per_step"], r["snes_iterations"]
    med = r["damage_ms_median"]
    lines.append(f"| {r['example']} | {r['dofs_zeta']} | {r['t_start']:.4g} | {ms['snes']:.3f} -> "
                 f"{ms['fast']:.3f} ({ms['snes'] / ms['fast']:.1f}x); {med['snes']:.3f} -> "
                 f"{med['fast']:.3f} | {c['damage_vi_fast_hits']} "
                 f"({c['damage_vi_fast_unchanged']}) / {c['damage_vi_fast_fallbacks']} / "
                 f"{c['damage_vi_fast_setups']} | {its['snes']} -> {its['fast']} | "
                 f"{r['nodes_at_zeta_star']} / {r['nodes_at_1']} | "
                 f"{max(r['max_relative_difference'].values()):.1e} |")
write_record(args.out, stem, rows, lines,
             command=" ".join(["benchmarks/damage_fast_path.py", *sys.argv[1:]]))
