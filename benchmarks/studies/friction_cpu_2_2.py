"""Thesis Tables 2.2/2.3 on this machine: CPU time of Section 2.2 Example 1 for the three
friction solvers side by side, n in {16, 32, 64, 128} x k in {0.02, 0.01, 0.005, 0.002}.

    .venv/bin/python benchmarks/studies/friction_cpu_2_2.py [--n 16 32 64 128] [--k 0.02 ...]
                                                    [--budget 600] [--out results/bench/friction_cpu]
                                                    [--set g_fric=200 rho_uzawa=1e-3] [--render]

Each (solver, n, k) cell is one full run (T = 1) with the thesis stopping test (relative
V-change 1e-6 for Uzawa and penalty-duality, eps_reg = 1e-9 for Newton and penalty-duality).
A run that exceeds the budget (default 600 s) is stopped and the solver's larger cells are
skipped ("-"). Also reported per cell: the floor (one linear solve with the factorised operator
per time step, plus the damage steps), and the relative V-norm distance of the final
displacements of Uzawa and penalty-duality to Newton's. Writes cpu.csv, cpu.md, cpu.json.
"""
import argparse
import json
import time
from pathlib import Path

import numpy as np
import ufl
from mpi4py import MPI

import sys
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the checkout: reproduction/
import reproduction.baselines  # noqa: E402,F401 (registers uzawa and penalty-duality)
from damage_dolfinx import compat  # noqa: E402
from damage_dolfinx.catalogue import examples
from damage_dolfinx.runtime import runner
from damage_dolfinx.forms.constitutive import eps
from damage_dolfinx.numerics.solvers import ConvergenceError

SOLVERS = ("newton", "uzawa", "penalty-duality")
parser = argparse.ArgumentParser()
parser.add_argument("--n", type=int, nargs="+", default=[16, 32, 64, 128])
parser.add_argument("--k", type=float, nargs="+", default=[0.02, 0.01, 0.005, 0.002])
parser.add_argument("--budget", type=float, default=600.0)
parser.add_argument("--out", default="results/bench/friction_cpu")
parser.add_argument("--set", nargs="*", default=[], metavar="KEY=VALUE",
                    help="parameter overrides for every run, e.g. g_fric=200 rho_uzawa=1e-3")
parser.add_argument("--render", action="store_true",
                    help="only rewrite cpu.md from OUT/cpu.json and the run folders")
args = parser.parse_args()
extra = dict(item.split("=", 1) for item in args.set)
comm = MPI.COMM_WORLD
out = Path(args.out)


def v_distance(a, b, msh_ref):
    """||eps(u_a - u_b)|| / ||eps(u_b)|| from the gathered final fields (same mesh)."""
    da, db = np.load(a / "fields_final.npz"), np.load(b / "fields_final.npz")
    V = compat.vector_p1(msh_ref)
    from dolfinx import fem
    fa, fb = fem.Function(V), fem.Function(V)
    X = V.tabulate_dof_coordinates()[:, :2]
    key = np.round(da["u_coords"], 10)
    order = {tuple(p): i for i, p in enumerate(map(tuple, key))}
    idx = np.array([order[tuple(p)] for p in np.round(X, 10)])
    fa.x.array[:] = da["u"][idx].reshape(-1)
    fb.x.array[:] = db["u"][idx].reshape(-1)
    diff = fem.Function(V)
    diff.x.array[:] = fa.x.array - fb.x.array
    n = lambda f: np.sqrt(compat.assemble_scalar(ufl.inner(eps(f), eps(f)) * ufl.dx, comm))  # noqa
    return float(n(diff) / n(fb))


def floor_time(n, k):
    """Damage steps + one factorised linear solve per time step (the cost floor)."""
    ex = examples.get("2.2-ex1")
    s = ex.build(comm, n=n, k=k, overrides={**extra, "friction_solver": "uzawa"})
    s.initialize()
    fr = s.friction
    start = time.perf_counter()
    for _ in range(s.num_steps):
        s.damage.solve()
        with fr.b0.localForm() as bl:
            bl.set(0.0)
        compat.assemble_vector(fr.b0, fr.l)
        fr.op.solve(fr.b0, compat.petsc_vec(s.v))
    return time.perf_counter() - start


def friction_seconds(row):
    """The friction-step time of each completed run (timings_s of its summary.json)."""
    for solver in SOLVERS:
        summary = out / f"{solver}_n{row['n']}_k{row['k']}" / "summary.json"
        if row.get(solver) is not None and summary.is_file():
            row[f"{solver}_friction_s"] = json.loads(summary.read_text())["timings_s"]["friction"]


def write_tables(rows):
    """cpu.json and cpu.md: whole-run wall times (the damage steps, common to all three solvers,
    included) and the friction-step times alone, with the ratios to Newton."""
    out.mkdir(parents=True, exist_ok=True)
    for row in rows:
        friction_seconds(row)
    (out / "cpu.json").write_text(json.dumps({"rows": rows, "budget_s": args.budget,
                                              "overrides": extra, "mpi_size": comm.size},
                                             indent=2))
    fmt = lambda v: "-" if v is None else f"{v:.1f}"  # noqa: E731
    lines = ["| n | k | Newton s | Uzawa s | penalty-duality s | floor s | Newton/floor | "
             "Uzawa/Newton | PD/Newton | friction step s: Newton / Uzawa / PD | "
             "Uzawa/Newton (friction) | PD/Newton (friction) | Uzawa-Newton (V) | "
             "PD-Newton (V) |", "|---" * 14 + "|"]
    for r in rows:
        def ratio(a, b):
            return "-" if r.get(a) is None or r.get(b) is None else f"{r[a] / r[b]:.1f}"
        steps = " / ".join("-" if r.get(f"{solver}_friction_s") is None
                           else f"{r[f'{solver}_friction_s']:.2f}" for solver in SOLVERS)
        lines.append(f"| {r['n']} | {r['k']} | {fmt(r['newton'])} | {fmt(r['uzawa'])} | "
                     f"{fmt(r['penalty-duality'])} | {r['floor_s']:.1f} | "
                     f"{ratio('newton', 'floor_s')} | {ratio('uzawa', 'newton')} | "
                     f"{ratio('penalty-duality', 'newton')} | {steps} | "
                     f"{ratio('uzawa_friction_s', 'newton_friction_s')} | "
                     f"{ratio('penalty-duality_friction_s', 'newton_friction_s')} | "
                     f"{r.get('uzawa_vs_newton_V', float('nan')):.1e} | "
                     f"{r.get('penalty-duality_vs_newton_V', float('nan')):.1e} |")
    (out / "cpu.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if args.render:  # tables only, from an earlier run's cpu.json and run folders
    if comm.rank == 0:
        write_tables(json.loads((out / "cpu.json").read_text())["rows"])
    raise SystemExit


rows, skipped = [], {solver: False for solver in SOLVERS}
for n in args.n:
    for k in args.k:
        row = {"n": n, "k": k, "floor_s": floor_time(n, k)}
        for solver in SOLVERS:
            folder = out / f"{solver}_n{n}_k{k}"
            if skipped[solver]:
                row[solver] = None
                continue
            try:
                s = runner.run("2.2-ex1", folder, n=n, k=k,
                               overrides={**extra, "friction_solver": solver}, progress=False,
                               figures=False, write_every=10**9, time_limit=args.budget)
                done = s["status"] == "completed"
                row[f"{solver}_iterations"] = s["iterations"]["friction"]
                row[f"{solver}_status"] = s["status"]
            except ConvergenceError as exc:
                done = False
                row[f"{solver}_status"] = f"failed: {exc}"
            row[solver] = s["wall_time_s"] if done else None
            skipped[solver] = not done
        ref = examples.get("2.2-ex1").build(comm, n=n, k=k).mesh
        for solver in ("uzawa", "penalty-duality"):
            if row[solver] is not None and row["newton"] is not None:
                row[f"{solver}_vs_newton_V"] = v_distance(out / f"{solver}_n{n}_k{k}",
                                                           out / f"newton_n{n}_k{k}", ref)
        rows.append(row)
        if comm.rank == 0:
            print(json.dumps(row), flush=True)

if comm.rank == 0:
    write_tables(rows)
