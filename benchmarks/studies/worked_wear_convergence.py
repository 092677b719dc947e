"""Convergence of the worked wear model (demos/demo_wear.py) in h and k against a fine
reference, on the demo's problem (a dragged Kelvin-Voigt block on a wearing foundation,
T = 1):

    python benchmarks/studies/worked_wear_convergence.py [--ref-n 32] [--ref-k 0.005]
        [--out benchmarks/reference_output/worked_wear]

Two measures:

* the package's study, ``dd.converge`` (errors max_n ||u - u_hk||_V + ||zeta - zeta_hk||_L2
  against the reference, the coarse fields transferred exactly to the nested reference mesh),
  levels n = ref/16 ... ref/2 and k = 4, 2, 1 times ref_k;
* the worn depth on Gamma_C at T: ||w_h - w_ref||_{L2(Gamma_C)} / ||w_ref||_{L2(Gamma_C)}
  (the coarse P1 profile evaluated at the reference nodes: exact on the nested, straight
  Gamma_C; the difference integrated exactly, piecewise linear), in h at k = ref_k and in k at
  n = ref_n (the time error alone; k = 8, 4, 2 times ref_k), with the worn volume's relative
  error; and the distance of each level to the next finer one, whose ratios give the order
  without the reference's bias (an error against a reference only twice finer is
  C (h^p - h_ref^p), not C h^p).

Rates: least-squares slopes of log(error) against log(h) or log(k), and the slope between the
two finest levels. Writes wear_errors.csv, converge_errors.csv and study.json to ``--out``
(the runs themselves in a temporary folder)."""
import argparse
import csv
import json
import runpy
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
from common import RECORDS  # noqa: E402

import damage_dolfinx as dd  # noqa: E402

DEMO = runpy.run_path(str(HERE.parents[1] / "demos" / "demo_wear.py"), run_name="study")


def final_profile(n, k, folder):
    """(x, w) along Gamma_C at T, and the worn volume, of the demo's problem at (n, k)."""
    problem = DEMO["make_problem"](n=n, k=k)
    with dd.steps(problem, folder, overwrite=True, progress=False, figures=False) as run:
        for step in run:
            last = step
    X, w, _ = DEMO["profile"](last.model)
    return X, w, last.model.scalars()["wear_volume"]


def l2_segments(X, f):
    """The L2 norm of the piecewise linear f on the nodes X (exact)."""
    a, b, h = f[:-1], f[1:], np.diff(X)
    return float(np.sqrt(np.sum(h * (a * a + a * b + b * b) / 3.0)))


def rate(sizes, errors):
    """(least-squares slope, slope of the two finest) of log error against log size."""
    s, e = np.log(np.asarray(sizes)), np.log(np.asarray(errors))
    return float(np.polyfit(s, e, 1)[0]), float((e[-1] - e[-2]) / (s[-1] - s[-2]))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--ref-n", type=int, default=32)
    ap.add_argument("--ref-k", type=float, default=0.005)
    ap.add_argument("--out", type=Path, default=RECORDS / "worked_wear")
    args = ap.parse_args()
    R, K = args.ref_n, args.ref_k
    ns = [R // 16, R // 8, R // 4, R // 2]
    ks = [8 * K, 4 * K, 2 * K]
    args.out.mkdir(parents=True, exist_ok=True)
    work = Path(tempfile.mkdtemp(prefix="worked_wear_"))
    start = time.perf_counter()
    runs = {(n, k): final_profile(n, k, work / f"n{n}_k{k:g}")
            for n, k in [(R, K)] + [(n, K) for n in ns] + [(R, k) for k in ks]}
    Xr, wr, vr = runs[(R, K)]
    norm = l2_segments(Xr, wr)

    def distance(a, b):      # ||w_a - w_b||_{L2(Gamma_C)} / ||w_ref||, on the reference nodes
        return l2_segments(Xr, np.interp(Xr, *runs[a][:2]) - np.interp(Xr, *runs[b][:2])) / norm
    rows = []
    for kind, levels in (("h", [(n, K) for n in ns + [R]]), ("k", [(R, k) for k in ks + [K]])):
        for i, (n, k) in enumerate(levels[:-1]):
            rows.append({"study": kind, "n": n, "h": 1.0 / (4 * n), "k": k,
                         "wear_L2_rel": distance((n, k), (R, K)),
                         "wear_L2_next": distance((n, k), levels[i + 1]),
                         "volume_rel": abs(runs[(n, k)][2] - vr) / vr,
                         "volume": runs[(n, k)][2]})
    study = dd.converge(DEMO["problem"], work / "converge", n=ns, k=ks[1:] + [K], ref_n=R,
                        ref_k=K, progress=False, overwrite=True)
    wall = time.perf_counter() - start
    shutil.rmtree(work, ignore_errors=True)

    def rates(kind, key):
        rs = [r for r in rows if r["study"] == kind]
        return dict(zip(("fit", "finest"), rate([r[kind] for r in rs], [r[key] for r in rs])))
    summary = {
        "command": "python benchmarks/studies/worked_wear_convergence.py"
                   f" --ref-n {R} --ref-k {K:g}",
        "reference": {"n": R, "h_gamma_c": 1.0 / (4 * R), "k": K, "worn_volume": vr},
        "wear_rate_h_vs_ref": rates("h", "wear_L2_rel"),
        "wear_rate_h_successive": rates("h", "wear_L2_next"),
        "volume_rate_h_vs_ref": rates("h", "volume_rel"),
        "wear_rate_k_vs_ref": rates("k", "wear_L2_rel"),
        "wear_rate_k_successive": rates("k", "wear_L2_next"),
        "converge_rates": study["rates"],
        "converge_error_definition": study["error_definition"],
        "wall_s": wall,
    }
    with open(args.out / "wear_errors.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    keys = ["n", "h", "k", "error", "error_u_V", "error_zeta_L2"]
    with open(args.out / "converge_errors.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
        writer.writeheader()
        writer.writerows(study["errors"])
    (args.out / "study.json").write_text(json.dumps(summary, indent=1) + "\n")
    for r in rows:
        print(f"{r['study']}: n = {r['n']:3d}, k = {r['k']:g}: wear L2 vs ref "
              f"{r['wear_L2_rel']:.3e}, vs next level {r['wear_L2_next']:.3e}, "
              f"volume {r['volume_rel']:.3e}")
    for e in study["errors"]:
        print(f"converge n = {e['n']}, k = {e['k']:g}: {e['error']:.3e}")
    print(json.dumps(summary, indent=1))


if __name__ == "__main__":
    main()
