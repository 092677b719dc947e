"""Convergence of the worked adhesion model (demos/demo_adhesion.py): a bonding field beta on
Gamma_C with its own evolution law, on a Kelvin-Voigt body with damage, the block pulled off its
foundation to T = 0.9 (the debonding front half-way).

    flock <lock> python benchmarks/studies/worked_adhesion_convergence.py
        [--ref-n 64] [--n 2 4 8 16 32] [--k 0.02] [--kn 16]
        [--ks 0.015 0.0075 0.00375 0.001875] [--ref-k 0.000375]
        [--out benchmarks/reference_output/worked_adhesion]

In h: ``dd.converge`` on the nested meshes n (4n x n cells) at the one time step k against the
reference n = ref_n at the same k (a spatial error only), every component's error the maximum
over the common time levels: ||u||_V, ||zeta||_L2 and ||beta||_L2(Gamma_C) (the norm of a field
on the contact boundary). In k: runs on the one mesh n = kn with the steps ks against the
reference step ref_k on that mesh (a temporal error only), the errors of the final state at T:
||beta - beta_ref||_L2(Gamma_C) (trapezoidal rule on the nodes of Gamma_C, exact for the P1
trace's nodal interpolant), max |u - u_ref| at the nodes, ||zeta - zeta_ref||_inf. Rates are
least-squares slopes of log error against log h (log k). Writes convergence.json (the numbers)
and rates.md (the tables) in the output folder; the runs go to a temporary folder."""
import argparse
import json
import runpy
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from common import RECORDS, REPO, commit  # noqa: E402

import damage_dolfinx as dd  # noqa: E402

DEMO = REPO / "demos" / "demo_adhesion.py"
HEADER = {"error_u_V": "u (V)", "error_zeta_L2": "zeta (L2)",
          "error_beta_L2_GammaC": "beta (L2(Gamma_C))", "error": "sum",
          "error_at_T": "sum at T"}


def slope(x, y):
    x, y = np.log(np.asarray(x, float)), np.log(np.asarray(y, float))
    return float(np.polyfit(x, y, 1)[0])


def final_fields(folder):
    data = np.load(folder / "fields_final.npz")
    return {k: data[k] for k in data.files}


def k_errors(run, ref):
    """Errors of the final state of ``run`` against ``ref`` (same mesh, same node order)."""
    xy = ref["beta_coords"]
    on = np.isclose(xy[:, 1], 0.0)
    x = xy[on, 0]
    d = (run["beta"][on, 0] - ref["beta"][on, 0]) ** 2
    order = np.argsort(x)
    beta = float(np.sqrt(np.trapz(d[order], x[order])))
    return {"beta_L2_GammaC": beta,
            "u_max": float(np.abs(run["u"] - ref["u"]).max()),
            "zeta_max": float(np.abs(run["zeta"] - ref["zeta"]).max())}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ref-n", type=int, default=64)
    ap.add_argument("--n", type=int, nargs="+", default=[2, 4, 8, 16, 32])
    ap.add_argument("--k", type=float, default=0.02)
    ap.add_argument("--kn", type=int, default=16)
    ap.add_argument("--ks", type=float, nargs="+", default=[0.015, 0.0075, 0.00375, 0.001875])
    ap.add_argument("--ref-k", type=float, default=0.000375)
    ap.add_argument("--T", type=float, default=0.9)
    ap.add_argument("--out", default=str(RECORDS / "worked_adhesion"))
    a = ap.parse_args()
    problem = runpy.run_path(str(DEMO), run_name="study")["problem"]
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    record = {"commit": commit(), "T": a.T, "command": " ".join(sys.argv[1:])}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        # -- in h
        start = time.perf_counter()
        study = dd.converge(problem, tmp / "h", n=a.n, k=[a.k], ref_n=a.ref_n, ref_k=a.k,
                            T=a.T, progress=False)
        rows = sorted(study["errors"], key=lambda r: r["n"])
        names = [key for key in rows[0] if key.startswith("error_") and key != "error_at_T"]
        names += ["error", "error_at_T"]     # their sum: max over the time levels, at T
        h = [r["h"] for r in rows] if "h" in rows[0] else [1.0 / r["n"] for r in rows]
        record["h"] = {"ref_n": a.ref_n, "k": a.k, "seconds": time.perf_counter() - start,
                       "norm": study.get("norm"), "error_definition": study.get("error_definition"),
                       "rows": [{"n": r["n"], "h": hh, **{k: r[k] for k in names}}
                                for r, hh in zip(rows, h)],
                       "rates": {k: slope(h, [r[k] for r in rows]) for k in names},
                       "rates_last_pair": {k: slope(h[-2:], [r[k] for r in rows[-2:]])
                                           for k in names}}
        # -- in k
        start = time.perf_counter()
        runs = {}
        for k in sorted(set(a.ks) | {a.ref_k}):
            folder = tmp / f"k{k:g}"
            dd.run(problem, folder, n=a.kn, k=k, T=a.T, progress=False, figures=False,
                   overwrite=True)
            runs[k] = final_fields(folder)
        ks = sorted(a.ks, reverse=True)
        errs = [k_errors(runs[k], runs[a.ref_k]) for k in ks]
        record["k"] = {"n": a.kn, "ref_k": a.ref_k, "seconds": time.perf_counter() - start,
                       "rows": [{"k": k, **e} for k, e in zip(ks, errs)],
                       "rates": {c: slope(ks, [e[c] for e in errs]) for c in errs[0]},
                       "rates_last_pair": {c: slope(ks[-2:], [e[c] for e in errs[-2:]])
                                           for c in errs[0]}}
    if MPI.COMM_WORLD.rank:
        return
    (out / "convergence.json").write_text(json.dumps(record, indent=1) + "\n")
    lines = [f"In h (k = {a.k:g}, reference n = {a.ref_n}, T = {a.T:g}); error = max over the "
             "time levels:", "",
             "| n | h | " + " | ".join(HEADER.get(k, k) for k in names) + " |", "|---" * (len(names) + 2) + "|"]
    for r in record["h"]["rows"]:
        lines.append(f"| {r['n']} | {r['h']:.4g} | " + " | ".join(f"{r[k]:.3e}" for k in names)
                     + " |")
    lines.append("| rate (fit) | | " + " | ".join(f"{record['h']['rates'][k]:.2f}"
                                                  for k in names) + " |")
    lines.append("| rate (last pair) | | " + " | ".join(
        f"{record['h']['rates_last_pair'][k]:.2f}" for k in names) + " |")
    comps = list(record["k"]["rows"][0])[1:]
    lines += ["", f"In k (n = {a.kn}, reference k = {a.ref_k:g}, T = {a.T:g}); error of the "
              "final state:", "", "| k | " + " | ".join(comps) + " |",
              "|---" * (len(comps) + 1) + "|"]
    for r in record["k"]["rows"]:
        lines.append(f"| {r['k']:g} | " + " | ".join(f"{r[c]:.3e}" for c in comps) + " |")
    lines.append("| rate (fit) | " + " | ".join(f"{record['k']['rates'][c]:.2f}"
                                               for c in comps) + " |")
    lines.append("| rate (last pair) | " + " | ".join(
        f"{record['k']['rates_last_pair'][c]:.2f}" for c in comps) + " |")
    (out / "rates.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
