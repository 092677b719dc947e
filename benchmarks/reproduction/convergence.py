"""Convergence tables of the thesis examples, in parallel.

    mpirun -n 2 .venv/bin/python benchmarks/reproduction/convergence.py 2.3-ex1 [--quick] [--out DIR]
    mpirun -n 2 .venv/bin/python benchmarks/reproduction/convergence.py 2.4-ex1 --set friction_law=coulomb

Runs the example's default study (reference and coarse (n, k) from the catalogue, e.g. 2.3-ex1:
reference n = 256, k = 5e-4; n in {4, ..., 128} x k in {0.05, ..., 0.001}); writes errors.csv,
errors.md, convergence.png and summary.json (with wall times and MPI size) under
results/convergence/<id>. ``--quick``: the three coarsest meshes and largest time steps of the example against reference
n = 4 x the second mesh, k = half the smallest step (seconds to minutes). For other sizes use ``damage-dolfinx converge ID --ref-n --ref-k --n --k``.
"""
import argparse

from mpi4py import MPI

from damage_dolfinx.studies import convergence
from damage_dolfinx.catalogue import examples

parser = argparse.ArgumentParser()
parser.add_argument("id")
parser.add_argument("--quick", action="store_true")
parser.add_argument("--out", default=None)
parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                    help="model parameter override, e.g. --set friction_law=coulomb (2.4-ex1 P2)")
parser.add_argument("--reading", choices=("literal", "evidence"),
                    help="thesis data literally or the evidence reading")
args = parser.parse_args()
overrides = dict(pair.split("=", 1) for pair in args.set)
if args.reading:
    overrides["reading"] = args.reading
out = args.out or f"results/convergence/{args.id}" + ("-quick" if args.quick else "")
if args.quick:
    study = examples.get(args.id, args.reading).convergence
    ns, ks = sorted(study["n"])[:3], sorted(study["k"], reverse=True)[:3]
    s = convergence.study(args.id, out, ref_n=4 * ns[1], ref_k=ks[-1] / 2, ns=ns, ks=ks,
                          overrides=overrides)
else:
    s = convergence.study(args.id, out, overrides=overrides)
if MPI.COMM_WORLD.rank == 0:
    print(f"wall time {s['wall_time_s']:.1f} s on {s['mpi_size']} rank(s); reference run "
          f"{s['reference']['wall_time_s']:.1f} s; rates {s['rates']}")
