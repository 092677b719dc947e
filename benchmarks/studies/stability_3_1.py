"""Time-step limits of the explicit elastic/contact force (docs/models.md) and a measured onset.

    [mpirun -n 2] .venv/bin/python benchmarks/studies/stability_3_1.py [--out DIR] [--quick]

1. k_max of stability.py (SLEPc or power iteration) for the examples of Sections 3.1, 3.2 and 3.3
   on small meshes: 3.1 and 3.2 through their catalogue steppers (3.2 only if its catalogue is
   there), 3.3 Ex. 1-2 from the thesis data directly (square (0,6)^2, layout of 3.1 Ex. 1;
   viscosity eta_*(zeta) B/m_visc taken undamaged).
2. The measured onset for 3.1 Ex. 1 (G23, damage frozen, thesis load, T = 1): bisection on
   k/k_max with the chatter indicator max_n |second difference of ||v_n||_L2| / max_n ||v_n||
   (0.01 when smooth, > 0.1 beyond the limit), and what happens at the thesis' k columns.

Writes stability.json and stability.md under --out (default results/stability).
"""
import argparse
import json
import math
import time
from pathlib import Path

import numpy as np
import ufl
from mpi4py import MPI

from damage_dolfinx.numerics.stability_bound import exact_estimates
from damage_dolfinx import compat
from damage_dolfinx.catalogue import examples
from damage_dolfinx.numerics import stability
from damage_dolfinx.numerics.boundary import clamped
from damage_dolfinx.geometries import GAMMA_C, GAMMA_D, GAMMA_N
from damage_dolfinx.geometries.rectangle import rectangle, side
from damage_dolfinx.core.parameters import InputError

COMM = MPI.COMM_WORLD
#: indicator threshold between smooth and chattering runs (measured: 0.010-0.012 below k_max,
#: 0.13-0.78 at 1.1-1.2 k_max on n = 4)
CHATTER = 0.05


def catalogue_k_max(example_id, **mesh):
    """k_max (and details) that the example's stepper computes at construction."""
    ex = examples.get(example_id)
    start = time.perf_counter()
    with exact_estimates():
        st = ex.build(COMM, k=ex.k, T=ex.k, overrides={"stability_check": "warn"}, **mesh)
    info = dict(getattr(st, "stability", None) or {"k_max": getattr(st, "k_max", None)})
    info.update(example=example_id, mesh=mesh, k=ex.k, cells=st.mesh_info()["cells"],
                time_s=time.perf_counter() - start)
    return info


def square_3_3(n, E, nu, rho, m_visc, c_nu):
    """3.3 Ex. 1-2 setting: (0,6)^2, clamped at x = 0 and 6, contact below (thesis Section 3.3)."""
    geo = rectangle(COMM, (0, 0), (6, 6), n, n, {
        GAMMA_D: lambda x: side(0, 0.0)(x) | side(0, 6.0)(x), GAMMA_N: side(1, 6.0),
        GAMMA_C: side(1, 0.0)})
    V = compat.vector_p1(geo.mesh)
    ds = ufl.Measure("ds", domain=geo.mesh, subdomain_data=geo.facet_tags)
    start = time.perf_counter()
    out = stability.estimate_stability(V, E, nu, rho, m_visc, c_nu, ds(GAMMA_C),
                                       [clamped(V, geo.facet_tags, GAMMA_D)])
    out.update(mesh={"n": n}, cells=2 * n * n, time_s=time.perf_counter() - start)
    return out


def chatter(n, k_over_k_max=None, k=None):
    """Indicator and k of a 3.1 Ex. 1 run (damage frozen, T = 1) at k = f k_max (k = 1/N)."""
    ex = examples.get("3.1-ex1")
    with exact_estimates():
        k_max = ex.build(COMM, n=n, k=1e-3, T=1e-3).stability["k_max"]
    N = int(round(1.0 / (k if k is not None else k_over_k_max * k_max)))
    st = ex.build(COMM, n=n, k=1.0 / N, T=1.0,
                  overrides={"damage_active": False, "stability_check": "off"})
    st.initialize()
    v = []
    while st.n < st.num_steps:
        st.advance()
        v.append(st.scalars()["v_L2"])
    v = np.array(v)
    return {"k": 1.0 / N, "k_over_k_max": 1.0 / (N * k_max), "indicator":
            float(np.abs(np.diff(v, 2)).max() / v.max()), "v_L2_max": float(v.max()),
            "k_max": k_max}


def measured_onset(n, lo=0.5, hi=2.0, steps=7):
    """Bisection on k/k_max between a smooth (lo) and a chattering (hi) run."""
    runs = [chatter(n, lo), chatter(n, hi)]
    if runs[0]["indicator"] >= CHATTER or runs[1]["indicator"] < CHATTER:
        raise RuntimeError(f"onset not bracketed at n = {n}: {runs}")
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        r = chatter(n, mid)
        runs.append(r)
        lo, hi = (mid, hi) if r["indicator"] < CHATTER else (lo, mid)
    return {"n": n, "k_max_helper": runs[0]["k_max"], "onset_k_over_k_max": [lo, hi],
            "onset_k": [lo * runs[0]["k_max"], hi * runs[0]["k_max"]], "runs": runs}


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--out", default="results/stability")
    parser.add_argument("--quick", action="store_true", help="fewer meshes, n = 4 onset only")
    args = parser.parse_args()
    quick = args.quick
    table = []
    for n in ([4, 16] if quick else [4, 8, 16, 32, 64]):
        table.append(catalogue_k_max("3.1-ex1", n=n))
    for n in ([10] if quick else [10, 30]):
        table.append(catalogue_k_max("3.1-ex2", n=n))
    for h in ([0.25] if quick else [0.25, 0.125, 0.0625, 1 / 32]):
        table.append(catalogue_k_max("3.1-ex3", h=h))
    for example_id, meshes in (("3.2-ex1", [4, 16, 64]), ("3.2-ex2", [5, 20]),
                               ("3.2-ex3", [5, 20])):
        for n in meshes[:2] if quick else meshes:
            try:
                table.append(catalogue_k_max(example_id, n=n))
            except InputError as exc:  # 3.2 catalogue not there (yet)
                table.append({"example": example_id, "skipped": str(exc)})
                break
    for n in ([4, 16] if quick else [4, 16, 32]):
        row = square_3_3(n, 100.0, 0.3, 2700.0, 1.0, 2e3)
        row.update(example="3.3-ex1 (thesis data)", k=None)
        table.append(row)
        row = square_3_3(n, 7.1e9, 0.33, 2700.0, 1e6, 1e9)
        row.update(example="3.3-ex2 (thesis data)", k=None)
        table.append(row)

    onsets = [measured_onset(n) for n in ([4] if quick else [4, 8])]
    thesis_columns = [chatter(8, k=k) for k in (0.05, 0.02, 0.01, 0.005)]
    if COMM.rank == 0:
        write(Path(args.out), table, onsets, thesis_columns)


def fmt(x, spec=".4g"):
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, spec)


def write(out, table, onsets, thesis_columns):
    out.mkdir(parents=True, exist_ok=True)
    (out / "stability.json").write_text(json.dumps(
        {"k_max": table, "onsets_3_1_ex1": onsets, "thesis_columns_3_1_ex1_n8": thesis_columns,
         "mpi_size": COMM.size}, indent=2, default=str))
    lines = ["# Time-step limits of the explicit elastic/contact force (stability.py)", "",
             "| example | mesh | cells | omega^2_max | k_max (scheme) | closed form 1/m + sqrt(1/m^2 + 4/omega^2) "
             "| default k | k/k_max | s |", "|---|---|---|---|---|---|---|---|---|"]
    for r in table:
        if "skipped" in r:
            lines.append(f"| {r['example']} | skipped: {r['skipped'][:60]} | | | | | | | |")
            continue
        ratio = r["k"] / r["k_max"] if r.get("k") and r.get("k_max") else None
        lines.append(f"| {r['example']} | {r['mesh']} | {r['cells']} | {fmt(r.get('omega2_max'))} "
                     f"| {fmt(r.get('k_max'))} | {fmt(r.get('k_max_proportional_formula'))} "
                     f"| {fmt(r.get('k'))} | {fmt(ratio, '.3g')} | {r['time_s']:.2f} |")
    lines += ["", "## Measured onset, 3.1 Ex. 1 (damage frozen, T = 1)", "",
              "| n | helper k_max | measured onset k | onset / k_max |", "|---|---|---|---|"]
    for o in onsets:
        a, b = o["onset_k"]
        lines.append(f"| {o['n']} | {o['k_max_helper']:.5g} | {a:.5g} ... {b:.5g} | "
                     f"{o['onset_k_over_k_max'][0]:.3f} ... {o['onset_k_over_k_max'][1]:.3f} |")
    lines += ["", "## Thesis columns of Table 3.1 at n = 8 (G23)", "",
              "| k | k/k_max | chatter indicator | max ||v||_L2 |", "|---|---|---|---|"]
    for r in thesis_columns:
        lines.append(f"| {r['k']:g} | {r['k_over_k_max']:.3g} | {r['indicator']:.3f} "
                     f"| {r['v_L2_max']:.4g} |")
    text = "\n".join(lines) + "\n"
    (out / "stability.md").write_text(text)
    print(text, flush=True)


if __name__ == "__main__":
    main()
