"""Convergence of the worked temperature model (demos/demo_thermal_damage.py): the Kelvin-Voigt
bar with damage and a temperature with its own heat equation, in h and in k.

    .venv/bin/python benchmarks/studies/worked_thermal_convergence.py [--ref-n 256]
        [--n 8 16 32 64] [--k 0.025] [--k-mesh 16] [--ks 0.1 0.05 0.025 0.0125]
        [--ref-k 0.0015625] [--out results/worked_thermal] [--record DIR]

In h: ``dd.converge`` on the demo's mesh family (the bar (0,1)x(0,0.25), 4n x n cells, nested)
at one k for every level and the reference, so that the errors are the spatial errors alone:
e(n) = max over the time levels of ||u - u_h||_V + ||zeta - zeta_h||_L2 + ||theta - theta_h||_L2
(the model's ``error_components``), and each component on its own (errors.csv).
In k: runs on one mesh (``--k-mesh``) with the steps ``--ks`` against a run with ``--ref-k``
on the same mesh, so that the errors are the time errors alone: the relative nodal RMS
difference of u, zeta and theta at T (on the uniform grid, equivalent to the relative L2 norm).
Rates are least-squares slopes of log(error) against log(h) or log(k); in h also over the
levels n <= ref_n/4 only and pair by pair (an error against a reference only 2x finer is
underestimated by the factor 1 - 2^-p, against 4x finer by 1 - 4^-p: the last pair's slope is
inflated). Writes under --out:
h/ (the study's errors.csv, errors.md, summary.json, convergence.png), k_errors.csv and
worked_thermal_convergence.json; --record copies the small text records to DIR.
"""
import argparse
import csv
import json
import os
import runpy
import shutil
import sys
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from common import REPO, commit  # noqa: E402

import damage_dolfinx as dd  # noqa: E402

COMM = MPI.COMM_WORLD
DEMO = REPO / "demos" / "demo_thermal_damage.py"


def slope(x, y) -> float:
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


def fields(folder) -> dict:
    with np.load(Path(folder) / "fields_final.npz") as data:
        return {key: data[key] for key in ("u", "zeta", "theta")}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ref-n", type=int, default=256)
    parser.add_argument("--n", type=int, nargs="+", default=[8, 16, 32, 64])
    parser.add_argument("--k", type=float, default=0.025, help="the step of the h study")
    parser.add_argument("--k-mesh", type=int, default=16, help="the mesh level of the k study")
    parser.add_argument("--ks", type=float, nargs="+", default=[0.1, 0.05, 0.025, 0.0125])
    parser.add_argument("--ref-k", type=float, default=0.0015625)
    parser.add_argument("--out", default="results/worked_thermal")
    parser.add_argument("--record", default=None, help="copy the text records to this folder")
    args = parser.parse_args()
    out = Path(args.out)
    os.environ.pop("DAMAGE_DOLFINX_DEMO_OUT", None)      # the demo's model and problem only
    problem = runpy.run_path(str(DEMO), run_name="worked_thermal_convergence")["problem"]

    # -- in h: the package's study at one k
    start = time.perf_counter()
    h_study = dd.converge(problem, out / "h", n=args.n, k=[args.k], ref_n=args.ref_n,
                          ref_k=args.k, progress=False, overwrite=True)
    h_wall = time.perf_counter() - start
    rows = h_study["errors"]
    with open(out / "h" / "errors.csv") as f:
        table = list(csv.DictReader(f))
    hs = np.array([float(r["h"]) for r in table])
    far = np.array([int(r["n"]) * 4 <= args.ref_n for r in table])  # n <= ref_n / 4
    columns = {"total": "error", **{c[len("error_"):]: c for c in table[0]
                                    if c.startswith("error_") and c != "error_at_T"}}
    h_rates, h_rates_far, h_pairwise = {}, {}, {}
    for name, column in columns.items():
        e = np.array([float(r[column]) for r in table])
        h_rates[name] = slope(hs, e)
        h_rates_far[name] = slope(hs[far], e[far]) if far.sum() >= 2 else None
        h_pairwise[name] = [float(np.log(e[i] / e[i + 1]) / np.log(hs[i] / hs[i + 1]))
                            for i in range(len(e) - 1)]

    # -- in k: one mesh, against a fine step on it
    start = time.perf_counter()
    ref_folder = out / "k" / f"ref_k{args.ref_k:g}"
    dd.run(problem, ref_folder, n=args.k_mesh, k=args.ref_k, progress=False, figures=False,
           overwrite=True)
    ref = fields(ref_folder)
    k_rows = []
    for k in args.ks:
        folder = out / "k" / f"k{k:g}"
        dd.run(problem, folder, n=args.k_mesh, k=k, progress=False, figures=False,
               overwrite=True)
        got = fields(folder)
        errs = {name: float(np.sqrt(np.mean((got[name] - ref[name]) ** 2))
                            / np.sqrt(np.mean(ref[name] ** 2))) for name in ref}
        k_rows.append({"k": k, **errs})
    k_wall = time.perf_counter() - start
    k_rates = {name: slope([r["k"] for r in k_rows], [r[name] for r in k_rows])
               for name in ("u", "zeta", "theta")}

    record = {
        "problem": "demos/demo_thermal_damage.py, the bar (0,1)x(0,0.25), T = "
                   f"{problem.T:g}, default data",
        "h_study": {"ref_n": args.ref_n, "n": args.n, "k": args.k,
                    "error_definition": h_study.get("error_definition"),
                    "errors": rows, "rates": h_rates,
                    "rates_n_at_most_ref_n_over_4": h_rates_far,
                    "pairwise_slopes": h_pairwise,
                    "package_rates": h_study["rates"], "wall_time_s": h_wall},
        "k_study": {"mesh_n": args.k_mesh, "ref_k": args.ref_k, "errors": k_rows,
                    "error_definition": "relative nodal RMS difference at T from the run "
                                        "with ref_k on the same mesh",
                    "rates": k_rates, "wall_time_s": k_wall},
        "commit": commit(), "mpi_size": COMM.size,
        "date": time.strftime("%Y-%m-%d", time.gmtime()),
    }
    if COMM.rank == 0:
        with open(out / "k_errors.csv", "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=["k", "u", "zeta", "theta"])
            writer.writeheader()
            writer.writerows(k_rows)
        (out / "worked_thermal_convergence.json").write_text(json.dumps(record, indent=1))
        print("h study (k = %g, reference n = %d):" % (args.k, args.ref_n))
        for r in table:
            print("  n = %3s  h = %.4g  error %.4e  (u %.3e, zeta %.3e, theta %.3e)" % (
                r["n"], float(r["h"]), float(r["error"]), float(r["error_u_V"]),
                float(r["error_zeta_L2"]), float(r["error_theta_L2"])))
        print("  rates in h: " + ", ".join(f"{k} {v:.2f}" for k, v in h_rates.items()))
        if all(v is not None for v in h_rates_far.values()):
            print(f"  rates in h, n <= {args.ref_n // 4}: "
                  + ", ".join(f"{k} {v:.2f}" for k, v in h_rates_far.items()))
        print("  pairwise slopes: " + "; ".join(
            f"{k} " + " ".join(f"{v:.2f}" for v in vals) for k, vals in h_pairwise.items()))
        print("k study (n = %d, reference k = %g):" % (args.k_mesh, args.ref_k))
        for r in k_rows:
            print("  k = %-7g u %.3e  zeta %.3e  theta %.3e" % (r["k"], r["u"], r["zeta"],
                                                                r["theta"]))
        print("  rates in k: " + ", ".join(f"{k} {v:.2f}" for k, v in k_rates.items()))
        print(f"wall time: h study {h_wall:.0f} s, k study {k_wall:.0f} s")
        if args.record:
            dest = Path(args.record)
            dest.mkdir(parents=True, exist_ok=True)
            for name in ("errors.csv", "errors.md", "summary.json"):
                shutil.copy(out / "h" / name, dest / f"h_{name}")
            for name in ("k_errors.csv", "worked_thermal_convergence.json"):
                shutil.copy(out / name, dest / name)


if __name__ == "__main__":
    main()
