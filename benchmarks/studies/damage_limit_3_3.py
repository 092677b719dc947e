"""Section 3.3 Example 2 (thesis Figures 3.17, 3.18): self-mending of an initially damaged patch
and damage growth at the top corners until zeta reaches zeta_star, for the initial damage
(a) 0.1 on [2.5,3.5]^2 and (b) 0.1 on [2.5,3.5]x[0,1].

    [mpirun -n 2] .venv/bin/python benchmarks/studies/damage_limit_3_3.py            # n = 8 (minutes)
    [mpirun -n 2] .venv/bin/python benchmarks/studies/damage_limit_3_3.py --n 16     # thesis mesh (G33)

The time step is 0.8 k_max or below (k_max from stability.py on the chosen mesh) and divides
0.5 s, unless --k is given. Each case stops when min zeta reaches zeta_star (G43) or at T = 7.5.
Prints, per case, the time at which zeta(0, 6) first reaches zeta_star, the stop time, and the
self-mending of the initially damaged patch (zeta at (3, 3) for (a), (3, 0) for (b), on the
profile line, every 0.5 s). Writes under --out (default results/damage_limit_3_3): the run
folders a/ and b/, profiles_a.csv, profiles_b.csv (zeta on the line x2 = 3 (a) or 0 (b) every
0.5 s and at the last step, G34), corner_a.csv, corner_b.csv (zeta(0, 6) vs t),
figure_3_17.png (a), figure_3_18.png (b) and damage_limit.json.
"""
import argparse
import csv
import json
import math
from pathlib import Path

from mpi4py import MPI

from damage_dolfinx.catalogue import examples
from damage_dolfinx.viz import post
from damage_dolfinx.runtime import runner

EXAMPLE = "3.3-ex2"
FIGURES = {"a": "figure_3_17.png", "b": "figure_3_18.png"}
PATCH = {"a": 3.0, "b": 3.0}  # x1 of the patch centre on the profile line (x2 = 3 or 0)

parser = argparse.ArgumentParser()
parser.add_argument("--n", type=int, default=8, help="cells per side (thesis reading: 16, G33)")
parser.add_argument("--k", type=float, help="time step (default: <= 0.8 k_max dividing 0.5 s)")
parser.add_argument("--T", type=float, default=7.5, help="upper bound of the run (thesis 7.5)")
parser.add_argument("--cases", nargs="+", default=["a", "b"], choices=["a", "b"])
parser.add_argument("--elastic-term", default="explicit", choices=["explicit", "implicit"],
                    help="implicit = G33 deviation (fast, not the thesis scheme)")
parser.add_argument("--out", default="results/damage_limit_3_3")
args = parser.parse_args()
comm = MPI.COMM_WORLD
out = Path(args.out)


def default_k(n):
    """The largest k = 0.5/N <= 0.8 k_max (stability.py on the n x n mesh, as in the run);
    T/N if T is not a multiple of 0.5 s."""
    from damage_dolfinx.numerics.stability import SAFETY
    probe = examples.get(EXAMPLE).build(comm, n=n, k=args.T / 1e6, T=args.T)
    k_max = probe.stability["k_max"]
    base = 0.5 if abs(args.T / 0.5 - round(args.T / 0.5)) < 1e-9 else args.T
    return base / math.ceil(base / (SAFETY * k_max)), k_max


def read_history(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return [float(r["t"]) for r in rows], [float(r["zeta_probe"]) for r in rows]


def write_csv(path, header, rows):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)


k_max = None
k = args.k
if k is None:
    k, k_max = default_k(args.n)
results = {}
for case in args.cases:
    overrides = {"initial_damage": case, "elastic_term": args.elastic_term}
    summary = runner.run(EXAMPLE, out / case, n=args.n, k=k, T=args.T, overrides=overrides,
                         progress=True, figures=False, comm=comm)
    if comm.rank != 0:
        continue
    prof = summary["profiles"]
    t, z = read_history(out / case / "history.csv")
    zeta_star = summary["parameters"]["zeta_star"]
    i = min(range(len(prof["x1"])), key=lambda j: abs(prof["x1"][j] - PATCH[case]))
    mending = {f"{ti:g}": zi[i] for ti, zi in zip(prof["times"], prof["zeta"])}
    mending[f"{prof['last_t']:g} (last)"] = prof["last_zeta"][i]
    write_csv(out / f"profiles_{case}.csv", ["t"] + [f"x1={x:g}" for x in prof["x1"]],
              [[ti] + zi for ti, zi in zip(prof["times"], prof["zeta"])]
              + [[prof["last_t"]] + prof["last_zeta"]])
    write_csv(out / f"corner_{case}.csv", ["t", "zeta_0_6"], list(zip(t, z)))
    post.plot_damage_profiles(prof, out / case / "history.csv", zeta_star, out / FIGURES[case],
                              f"Example 3.3-2 ({case}): damage profiles and damage at the corner (0, 6)")
    results[case] = {
        "n": args.n, "k": k, "k_max": summary.get("k_max", k_max), "elastic_term": args.elastic_term,
        "status": summary["status"], "t_stop": summary["t_final"],
        "corner_zeta_star_time": summary["probe_zeta_star_time"],
        "corner_zeta_final": summary["final"]["zeta_probe"],
        "patch_point": [PATCH[case], prof["x2"]], "patch_zeta": mending,
        "min_zeta_final": summary["final"]["zeta_min"], "steps": summary["steps_done"],
        "wall_time_s": summary["wall_time_s"], "mpi_size": comm.size}
    r = results[case]
    print(f"[{case}] n = {args.n}, k = {k:.4g} (k_max = {r['k_max']:.4g}), {r['elastic_term']}: "
          f"{r['status']} at t = {r['t_stop']:.4g} after {r['steps']} steps, "
          f"{r['wall_time_s']:.0f} s", flush=True)
    print(f"[{case}] zeta(0,6) reaches zeta_star at t = {r['corner_zeta_star_time']}; "
          f"zeta at {tuple(r['patch_point'])}: "
          + ", ".join(f"t={key}: {v:.3f}" for key, v in mending.items()), flush=True)
if comm.rank == 0:
    (out / "damage_limit.json").write_text(json.dumps(results, indent=2))
    print(f"results in {out}")
