"""Thesis Table 2.1 / Figure 2.2: convergence of Section 2.1 Example 1, in parallel.

    mpirun -n 2 .venv/bin/python benchmarks/convergence_2_1_ex1.py [--quick] [--out DIR]

Reference n = 160, k = 5e-4 (2000 steps); coarse n in {5, 10, 20, 40, 80} x k in {0.05, 0.02,
0.01, 0.005, 0.002, 0.001}, all run in lockstep with the reference (no stored history). Writes
errors.csv, errors.md, convergence.png and summary.json (with the wall time and MPI size) under
results/convergence/2.1-ex1. ``--quick``: reference n = 40, k = 0.005 (seconds).
"""
import argparse

from mpi4py import MPI

from damage_dolfinx import convergence

parser = argparse.ArgumentParser()
parser.add_argument("--quick", action="store_true")
parser.add_argument("--out", default="results/convergence/2.1-ex1")
args = parser.parse_args()
if args.quick:
    s = convergence.study("2.1-ex1", args.out + "-quick", ref_n=40, ref_k=0.005, ns=[5, 10, 20],
                          ks=[0.05, 0.02, 0.01])
else:
    s = convergence.study("2.1-ex1", args.out)
if MPI.COMM_WORLD.rank == 0:
    print(f"wall time {s['wall_time_s']:.1f} s on {s['mpi_size']} rank(s); reference run "
          f"{s['reference']['wall_time_s']:.1f} s; rates {s['rates']}")
