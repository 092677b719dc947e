"""Section 3.1 Example 3: the L-shaped body without and with damage (thesis Figures 3.7, 3.8).

    [mpirun -n 2] .venv/bin/python benchmarks/studies/lshape_3_1.py [--h 0.125] [--k 0.001] [--T 10.5]

Runs 3.1-ex3 twice (damage_active = 0, 1), prints the largest nodal displacement at T of both
runs and its increase in %, the damage reached and the cost per step, and draws the two runs side
by side (figstyle): figure_3_7.png (deformed mesh x10 over the initial outline, as the thesis
caption says, line 3404) and figure_3_8.png (von Mises norm of eps(u_T) on the undeformed body,
one colour scale for both panels). Default mesh
h = 1/8 (coarse, about 30 s serial); the thesis mesh --h 0.03125 [G26] takes about 2 minutes
(10 500 steps per run at k = 0.001: 3.5 ms/step frozen, 6.3 ms/step with damage). Writes
lshape_3_1.json and the PNGs under --out (default results/lshape_3_1).
"""
import argparse
import json
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from damage_dolfinx.catalogue import examples
from damage_dolfinx.viz import post

COMM = MPI.COMM_WORLD


def run(h, k, T, active):
    """One run of 3.1-ex3; returns (stepper, record)."""
    ex = examples.get("3.1-ex3")
    st = ex.build(COMM, h=h, k=k, T=T, overrides={"damage_active": bool(active)})
    start = time.perf_counter()
    st.initialize()
    u_max_t = []
    step_times = []
    while st.n < st.num_steps:
        t0 = time.perf_counter()
        st.advance()
        step_times.append(time.perf_counter() - t0)
        u_max_t.append(st.u_max())
    st.update_output()
    s = st.scalars()
    return st, {"damage_active": bool(active), "u_max_T": s["u_max"],
                "u_max_over_time": float(max(u_max_t)), "zeta_min": s["zeta_min"],
                "zeta_mean": s["zeta_mean"], "eps_u_L2": s["eps_u_L2"],
                "penetration_rms_T": s["penetration_rms"], "steps": st.num_steps,
                "ms_per_step": 1e3 * float(np.mean(step_times)),
                "timings_s": dict(st.timings), "wall_s": time.perf_counter() - start,
                "k_max": st.stability.get("k_max") or st.stability.get("k_max_lower_bound"), "mesh": st.mesh_info()}


def side_by_side(steppers, field_name, amplification, path, title, label, mesh_only=False):
    """Two panels (undamaged, damaged) of a DG0 field on x + amplification u, on one colour
    scale, or (``mesh_only``) their deformed meshes over the undeformed outline; drawn by
    figstyle; collective."""
    panels = [post.gather_cells(st.u, getattr(st, field_name), amplification) for st in steppers]
    outline = post.gather_cells(None, steppers[0].zeta, 0.0)
    if COMM.rank != 0:
        return
    from damage_dolfinx.viz import figstyle
    names = ("undamaged ($\\zeta$ = 1)", "damaged")
    data = [{"xy": xy, "values": vals, "name": field_name, "label": label, "title": name}
            for (xy, vals), name in zip(panels, names)]
    scale = figstyle.shared_limits([vals for _, vals in panels])
    figstyle.render_fields(data, path, title=title, amplification=amplification,
                           ref_xy=outline[0] if amplification else None, mesh_only=mesh_only,
                           limits={0: scale, 1: scale})


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--h", type=float, default=0.125)
    parser.add_argument("--k", type=float, default=None, help="default: the catalogue's k")
    parser.add_argument("--T", type=float, default=None, help="default: 10.5")
    parser.add_argument("--out", default="results/lshape_3_1")
    args = parser.parse_args()
    ex = examples.get("3.1-ex3")
    k, T = args.k or ex.k, args.T or ex.T
    out = Path(args.out)
    if COMM.rank == 0:
        out.mkdir(parents=True, exist_ok=True)
    runs = [run(args.h, k, T, active) for active in (0, 1)]
    steppers = [r[0] for r in runs]
    records = [r[1] for r in runs]
    increase = 100.0 * (records[1]["u_max_T"] / records[0]["u_max_T"] - 1.0)
    title = f"3.1-ex3, h = {args.h:g}, k = {k:g}, t = {T:g}"
    side_by_side(steppers, "von_mises_strain", 10.0, out / "figure_3_7.png",
                 f"{title}: deformed mesh, undeformed outline dashed", "", mesh_only=True)
    side_by_side(steppers, "von_mises_strain", 0.0, out / "figure_3_8.png",
                 f"{title}: strains at the final time", "von Mises norm of the strain [-]")
    summary = {"h": args.h, "k": k, "T": T, "mpi_size": COMM.size, "runs": records,
               "u_max_increase_percent": increase,
               "expected_increase_percent_1_over_zeta": 100.0 * (1.0 / records[1]["zeta_mean"] - 1.0)}
    if COMM.rank == 0:
        (out / "lshape_3_1.json").write_text(json.dumps(summary, indent=2, default=str))
        for r in records:
            print(f"damage_active={int(r['damage_active'])}: max |u| at T = {r['u_max_T']:.6e} "
                  f"(max over time {r['u_max_over_time']:.6e}), zeta min/mean {r['zeta_min']:.6f}/"
                  f"{r['zeta_mean']:.6f}, {r['steps']} steps, {r['ms_per_step']:.2f} ms/step, "
                  f"wall {r['wall_s']:.1f} s, k_max {r['k_max']:.4g}")
        print(f"increase of max |u| at T by damage: {increase:.4f} % "
              f"(1/zeta_mean - 1 = {summary['expected_increase_percent_1_over_zeta']:.4f} %)")
        print(f"figures: {out / 'figure_3_7.png'}, {out / 'figure_3_8.png'}")


if __name__ == "__main__":
    main()
