"""All convergence studies of the thesis (Tables 2.1, 2.4, 2.5, 2.6, 2.7, 3.1, 3.2, 3.3).

    python benchmarks/reproduction/convergence_all.py [--quick] [--np 2] [--out results/convergence] [--only ID ...]
                                         [--reading literal|evidence]

Each study runs as `mpirun -n NP damage-dolfinx converge ID` at the catalogue's thesis settings
(fine reference computed in parallel), writing errors.csv/.md, convergence.png (log-log with the
fitted rates) and summary.json (wall time of the reference run) into OUT/<id>[-variant];
OUT/index.json lists commands, rates and wall times.
"""
import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # benchmarks/: common.py
import common  # noqa: E402,F401  (puts the checkout on sys.path)
from reproduction import reproduce  # noqa: E402

p = argparse.ArgumentParser()
p.add_argument("--quick", action="store_true", help="three coarse meshes, small reference")
p.add_argument("--np", type=int, default=2, help="MPI ranks")
p.add_argument("--out", default=None)
p.add_argument("--only", nargs="+", help="example ids")
p.add_argument("--resume", action="store_true",
               help="keep the runs that completed in an earlier invocation into the same OUT")
p.add_argument("--reading", choices=("literal", "evidence"),
               help="thesis data literally or the evidence reading (default: each example's "
                    "default_reading)")
a = p.parse_args()
mode = "quick" if a.quick else "full"
out = Path(a.out or ("results/convergence-quick" if a.quick else "results/convergence"))
if a.np < 1:
    p.error(f"--np must be a whole number >= 1, got {a.np}")
if out.exists() and not out.is_dir():
    p.error(f"--out {str(out)!r} is a file, not a folder")
if a.only:
    known = {job.example for job in reproduce.convergence_jobs(mode, a.reading)}
    unknown = sorted(set(a.only) - known)
    if unknown:
        p.error(f"--only: no convergence study of {', '.join(unknown)}; the studies: "
                f"{', '.join(sorted(known))}")
index = reproduce.run_convergence(mode, out, a.np, a.only, a.resume, a.reading)
for s in index["studies"]:
    rate = s.get("rates", {}).get("h_plus_k_all")
    print(f"{s['example']} {s['variant']}: exit {s['returncode']}, {s['wall_time_s']} s, "
          f"rate in h + k {rate if rate is None else round(rate, 3)}")
print(f"total {index['wall_time_s']} s on {a.np} ranks -> {out}")
