"""The per-step backsolve of a 2-D direct solver against the number of unknowns, by ordering
and factorisation: what the time per step of the package's 2-D default path (a factorisation
kept over the steps, one or a few triangular solves a step) is made of, and whether another
ordering or factorisation makes it grow more slowly.

    [mpirun -n 2] .venv/bin/python benchmarks/performance/backsolve_2d.py run 2.1-ex1 --n 140 \\
        [--configs petsc_nd,mumps_metis]
    .venv/bin/python benchmarks/performance/backsolve_2d.py report

``run`` builds the example at size n with every system on CG + AMG (cheap to set up), takes two
steps, and for each configuration factorises the elasticity (2.1) or velocity (3.1) matrix once
(timed), then times ``--solves`` solves with the same right-hand side (the median is kept;
a configuration whose relative residual exceeds 1e-8, e.g. a failed factorisation, is left
out), and reads the number of entries of the factor (PETSc: the factor matrix's ``nz_used``; MUMPS:
INFOG(29), summed over ranks). Each solution is compared with the first configuration's.
One JSON per (example, n, ranks) in ``<out>/runs/`` (a later run replaces only its own
configurations' rows). ``report`` writes ``backsolve.md``: per
configuration and ranks, solve time and factor entries against the unknowns, the least-squares
exponents of both from about 1e4 unknowns on, and the solve time per factor entry (ns), which
isolates the memory traffic from the fill.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from common import REPO, commit, md_head, md_row  # noqa: E402

_PETSC = {"ksp_type": "preonly", "pc_type": "cholesky", "pc_factor_mat_solver_type": "petsc"}
_MUMPS = {"ksp_type": "preonly", "pc_type": "cholesky", "pc_factor_mat_solver_type": "mumps"}
#: configuration -> KSP options; the package's defaults are petsc_nd (serial) and mumps_lu
#: (parallel, LU with MUMPS's automatic ordering)
CONFIGS = {
    "petsc_nd": {**_PETSC, "pc_factor_mat_ordering_type": "nd"},
    "petsc_qmd": {**_PETSC, "pc_factor_mat_ordering_type": "qmd"},
    "petsc_amd": {**_PETSC, "pc_factor_mat_ordering_type": "amd"},
    "mumps_lu": {**_MUMPS, "pc_type": "lu"},
    "mumps_auto": _MUMPS,
    "mumps_amd": {**_MUMPS, "mat_mumps_icntl_7": 0},
    "mumps_pord": {**_MUMPS, "mat_mumps_icntl_7": 4},
    "mumps_metis": {**_MUMPS, "mat_mumps_icntl_7": 5},
    "mumps_metis_lu": {**_MUMPS, "pc_type": "lu", "mat_mumps_icntl_7": 5},
}
K = {"2.1-ex1": 0.01, "3.1-ex1": 0.005}
FIT_FROM_DOFS = 9e3  # the smallest size measured, 9 744 unknowns (2.1-ex1, n = 70)


def factor_entries(ksp, solver_type: str) -> float:
    """Entries of the factor (global)."""
    F = ksp.getPC().getFactorMatrix()
    if solver_type == "mumps":
        return float(F.getMumpsInfog(29))
    return float(F.getInfo()["nz_used"])


def measure(example: str, n: int, configs: list, solves: int) -> dict:
    from mpi4py import MPI
    from petsc4py import PETSc
    from damage_dolfinx.catalogue import examples
    comm = MPI.COMM_WORLD
    opts = PETSc.Options()
    for prefix in ("mech_", "damage_"):  # the stepping itself on AMG: cheap at every size
        opts[prefix + "amg_min_dofs"] = 0
    k = K[example]
    st = examples.get(example).build(comm, n=n, k=k, T=k * 3)
    st.initialize()
    st.advance()
    st.advance()
    A, b = st.mech.A, st.mech.b
    rows, ref = [], None
    for name in configs:
        cfg = CONFIGS[name]
        prefix = f"bs_{name}_"
        for key, value in cfg.items():
            opts[prefix + key] = value
        ksp = PETSc.KSP().create(comm)
        ksp.setOptionsPrefix(prefix)
        ksp.setOperators(A)
        ksp.setFromOptions()
        comm.Barrier()
        start = time.perf_counter()
        ksp.setUp()
        comm.Barrier()
        setup = time.perf_counter() - start
        x = b.duplicate()
        times = []
        for _ in range(solves):
            x.set(0.0)
            comm.Barrier()
            start = time.perf_counter()
            ksp.solve(b, x)
            comm.Barrier()
            times.append(time.perf_counter() - start)
        r = b.duplicate()
        A.mult(x, r)
        r.aypx(-1.0, b)
        residual = r.norm() / b.norm()  # a failed factorisation leaves x = 0: residual 1
        if not residual <= 1e-8:  # NaN too
            if comm.rank == 0:
                print(f"{name}: failed (relative residual {residual:.1e}), left out", flush=True)
            ksp.destroy()
            continue
        if ref is None:
            ref = x.copy()
        diff = (x - ref).norm() / ref.norm()
        row = {"config": name, "options": cfg, "setup_s": setup, "residual": residual,
               "solve_s": float(np.median(times)), "solve_times_s": times,
               "factor_entries": factor_entries(ksp, cfg["pc_factor_mat_solver_type"]),
               "rel_diff_to_first": float(diff)}
        rows.append(row)
        if comm.rank == 0:
            print(json.dumps({k: v for k, v in row.items() if k != "options"}), flush=True)
        ksp.destroy()
        x.destroy()
    return {"example": example, "n": n, "ranks": comm.size, "dofs": A.getSize()[0],
            "matrix_entries": float(A.getInfo()["nz_used"]), "solves": solves, "rows": rows,
            "commit": commit(), "date": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}


def fit(x, y) -> float:
    keep = [i for i, v in enumerate(x) if v >= FIT_FROM_DOFS]
    if len(keep) < 2:
        return float("nan")
    return float(np.polyfit(np.log([x[i] for i in keep]), np.log([y[i] for i in keep]), 1)[0])


def report(out: Path, record: Path):
    runs = sorted((json.loads(p.read_text()) for p in (out / "runs").glob("*.json")),
                  key=lambda r: (r["example"], r["ranks"], r["dofs"]))
    series = {}
    for run in runs:
        for row in run["rows"]:
            series.setdefault((run["example"], run["ranks"], row["config"]), []).append(
                (run["dofs"], row))
    head = ["example", "ranks", "configuration", "unknowns", "solve [ms]", "factor entries / N",
            "solve per entry [ns]", "factorise [s]", "exponent: solve / entries / factorise",
            "max rel. diff."]
    lines = [f"<!-- {time.strftime('%Y-%m-%d')}, commit {commit()}; backsolve_2d.py report -->",
             "", *md_head(head)]
    for (example, ranks, config), points in sorted(series.items()):
        dofs = [d for d, _ in points]
        solve = [r["solve_s"] for _, r in points]
        entries = [r["factor_entries"] for _, r in points]
        setup = [r["setup_s"] for _, r in points]
        cells = [example, ranks, config, " / ".join(f"{d:.3g}" for d in dofs),
                 " / ".join(f"{1e3 * s:.3g}" for s in solve),
                 " / ".join(f"{e / d:.0f}" for e, d in zip(entries, dofs)),
                 " / ".join(f"{1e9 * s / e:.2f}" for s, e in zip(solve, entries)),
                 " / ".join(f"{s:.3g}" for s in setup),
                 f"**{fit(dofs, solve):.2f}** / {fit(dofs, entries):.2f} / "
                 f"{fit(dofs, setup):.2f}",
                 f"{max(r['rel_diff_to_first'] for _, r in points):.0e}"]
        lines.append(md_row(cells))
    record.mkdir(parents=True, exist_ok=True)
    (record / "backsolve.md").write_text("\n".join(lines) + "\n")
    (record / "backsolve.json").write_text(json.dumps(runs, indent=1))
    print("\n".join(lines))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    one = sub.add_parser("run", help="factorise and solve one size by each configuration")
    one.add_argument("example", choices=list(K))
    one.add_argument("--n", type=int, required=True)
    one.add_argument("--configs", default="petsc_nd,mumps_lu,mumps_metis,mumps_pord",
                     help=f"comma-separated, of {', '.join(CONFIGS)}")
    one.add_argument("--solves", type=int, default=7)
    rep = sub.add_parser("report", help="table and exponents from the measured sizes")
    rep.add_argument("--record", default=str(REPO / "benchmarks" / "reference_output"
                                             / "scaling_2d"))
    for p in (one, rep):
        p.add_argument("--out", default=str(REPO / "results" / "backsolve_2d"))
    args = parser.parse_args(argv)
    out = Path(args.out)
    if args.command == "report":
        report(out, Path(args.record))
        return
    configs = args.configs.split(",")
    unknown = [c for c in configs if c not in CONFIGS]
    if unknown:
        parser.error(f"unknown configuration(s) {', '.join(unknown)}")
    run = measure(args.example, args.n, configs, args.solves)
    from mpi4py import MPI
    if MPI.COMM_WORLD.rank == 0:  # rows of other configurations at this size are kept
        target = out / "runs" / f"{args.example}_n{args.n}_p{run['ranks']}.json"
        target.parent.mkdir(parents=True, exist_ok=True)
        if target.exists():
            new = {row["config"] for row in run["rows"]}
            old = json.loads(target.read_text())["rows"]
            run["rows"] = [row for row in old if row["config"] not in new] + run["rows"]
        target.write_text(json.dumps(run, indent=1))


if __name__ == "__main__":
    main()
