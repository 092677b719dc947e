"""Compare a wrench run (wrench_3_3.py's wrench.json) with the committed thesis-size reference
(the same maximum interpenetration, von Mises peak and min zeta to 1e-6 relative, at
the same places).

    .venv/bin/python benchmarks/reproduction/wrench_check.py results/wrench_3_3/wrench.json
    .venv/bin/python benchmarks/reproduction/wrench_check.py RUN.json --out reference_output/wrench_3_3/X.json \\
        --note "what, when, where"

Prints one line per quantity; exits 1 if a value differs by more than --rtol or a place differs.
With --out it writes the comparison (and --note, the run's wall time and steps) as JSON.
"""
import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # benchmarks/: common.py
from common import RECORDS  # noqa: E402

REFERENCE = RECORDS / "wrench_3_3" / "wrench.json"
VALUES = ["max_penetration", "max_penetration_t", "penetration_at_T", "u_max_at_T",
          "zeta_min_at_T", "von_mises_max_at_T"]
PLACES = ["max_penetration_at", "von_mises_argmax_at_T", "zeta_argmin_at_T"]

parser = argparse.ArgumentParser()
parser.add_argument("run", help="wrench.json of the run to check")
parser.add_argument("--reference", default=str(REFERENCE))
parser.add_argument("--rtol", type=float, default=1e-6)
parser.add_argument("--out", help="write the comparison here (JSON)")
parser.add_argument("--note", default="")
args = parser.parse_args()
try:
    run, ref = (json.loads(Path(p).read_text()) for p in (args.run, args.reference))
except (OSError, ValueError) as err:
    sys.exit(f"wrench_check.py: cannot read {err}")
for key in ("h", "T", "steps"):
    if run.get(key) != ref.get(key):
        print(f"wrench_check.py: {key} = {run.get(key)} differs from the reference's "
              f"{ref.get(key)}: not the same run", file=sys.stderr)
        sys.exit(2)

out, ok = {}, True
for key in VALUES:
    a, b = float(run[key]), float(ref[key])
    rel = abs(a - b) / max(abs(b), 1e-300)
    ok &= rel <= args.rtol
    out[key] = {"this_run": a, "committed": b, "relative_difference": rel}
    print(f"{key:22s} {a:.12e} (reference {b:.12e}) relative difference {rel:.2e}")
for key in PLACES:
    equal = run[key] == ref[key]
    ok &= equal
    out[key] = {"equal": equal}
    print(f"{key:22s} {'same place' if equal else 'DIFFERENT place'} {run[key]}")
print(f"wall time {run['wall_time_s']:.1f} s for {run['steps']} steps "
      f"({run['wall_time_s'] / run['steps'] * 1e6:.0f} us per step); "
      + ("equal to the reference" if ok else f"NOT equal to the reference at rtol {args.rtol}"))
if args.out:
    Path(args.out).write_text(json.dumps({
        "note": args.note, "run": args.run, "steps": run["steps"],
        "runner_wall_time_s": run["wall_time_s"], "rtol": args.rtol, "equal": bool(ok),
        "against_committed_reference": out}, indent=1) + "\n")
sys.exit(0 if ok else 1)
