"""The masonry barrel vault in 3-D (example 2.1-ex3-vault) against the 2-D arch.

    .venv/bin/python benchmarks/studies/vault_3d.py [--h 0.1]
        [--cases arch2d vault thin plane_strain] [--out results/bench/vault_3d]
        [--ref benchmarks/reference_output/vault_3d] [--plot-only]

Runs, each into OUT/<case> (XDMF, history.csv, summary.json), all with the data of 2.1-ex3
(calibrated 4500 kN/s, evidence reading) at element size h:

  arch2d        2.1-ex3: the 2-D arch ring, plane stress, unit thickness (the 94.5 kN reference)
  vault         2.1-ex3-vault: W = 1 m, n_W = round(W/h) layers, free ends (the catalogue entry)
  thin          W = 0.1 m, one layer, free ends: the plane-stress-like limit
  plane_strain  W = 0.1 m, one layer, u_z = 0 on both ends: a slice of an infinitely long vault

and the elastic check 'stiffness': the downward displacement of the load strip under self weight
alone (t = 0, zeta = 1) of a thin vault (W = 0.05, one layer) and of the plane-strain slice,
relative to the 2-D arch at h = 0.2, 0.1, 0.05, with nu = 0.49 (the thesis) and nu = 0.3.
Exact elasticity gives ~1 (thin, plane stress) and 1 - nu^2 (plane strain; 0.76 at nu = 0.49);
linear tetrahedra lock at nu = 0.49, which this measures.

Writes in REF: vault_3d.json (every number), vault_3d.md (tables), hinge_lines.png (the vault at
collapse: unrolled zeta on extrados and intrados, D_j, hinge lines), load_displacement.png (all
cases), section_damage.png (D_j against the angle from the left springing, all cases), and the
catalogue figures of the vault run (vault_slices.png, load_history.png).
"""
import argparse
import dataclasses
import json
import shutil
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

CASES = {"arch2d": ("2.1-ex3", None, "2-D arch (plane stress)"),
         "vault": ("2.1-ex3-vault", {"width": 1.0}, "vault W = 1 m, free ends"),
         "thin": ("2.1-ex3-vault", {"width": 0.1, "n_width": 1}, "vault W = 0.1 m, free ends"),
         "plane_strain": ("2.1-ex3-vault", {"width": 0.1, "n_width": 1, "ends": "plane_strain"},
                          "plane strain (u_z = 0 on the ends)")}


def parse():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--h", type=float, default=0.1)
    p.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    p.add_argument("--out", default="results/bench/vault_3d")
    p.add_argument("--ref", default="benchmarks/reference_output/vault_3d")
    p.add_argument("--plot-only", action="store_true", help="redraw from OUT")
    p.add_argument("--no-stiffness", action="store_true")
    return p.parse_args()


def run_case(case, h, out, comm):
    from damage_dolfinx.runtime import runner
    from damage_dolfinx.catalogue import bridge
    ex_id, geometry, _ = CASES[case]
    saved = dict(bridge.VAULT_GEOMETRY)
    if geometry is not None:
        bridge.VAULT_GEOMETRY.clear()
        bridge.VAULT_GEOMETRY.update(geometry)
    try:
        return runner.run(ex_id, out / case, h=h, progress=comm.rank == 0,
                          figures=case == "vault", comm=comm)
    finally:
        bridge.VAULT_GEOMETRY.clear()
        bridge.VAULT_GEOMETRY.update(saved)


def stiffness(comm):
    """u_y of the load strip under self weight (t = 0): 3-D / 2-D at three h, two nu."""
    from damage_dolfinx.catalogue import examples
    from damage_dolfinx.geometries.vault import barrel_vault
    rows = []

    def u_load(ex_id, h, nu, geometry=None):
        ex = examples.get(ex_id)
        ex = dataclasses.replace(ex, params=dataclasses.replace(ex.params, nu=nu))
        if geometry:
            ex = dataclasses.replace(ex, mesh=lambda c, n, hh: barrel_vault(
                c, h=hh, **geometry))
        stepper = ex.build(comm, h=h, k=0.001, T=0.001)
        stepper.initialize()
        return stepper.scalars()["u_load_y"]

    for nu, hs in ((0.49, (0.2, 0.1, 0.05)), (0.3, (0.1,))):
        for h in hs:
            ref = u_load("2.1-ex3", h, nu)
            thin = u_load("2.1-ex3-vault", h, nu, {"width": 0.05, "n_width": 1})
            strain = u_load("2.1-ex3-vault", h, nu, {"width": 0.05, "n_width": 1,
                                                     "ends": "plane_strain"})
            rows.append({"nu": nu, "h": h, "u_2d_mm": 1e3 * ref, "thin_ratio": thin / ref,
                         "plane_strain_ratio": strain / ref, "plane_strain_exact": 1 - nu**2})
    return rows


def case_record(summary):
    keep = ("failure_load_kN", "failure_step", "failure_time", "zeta_min_run", "n_hinges",
            "n_mechanism_hinges", "wall_time_s", "steps_done", "iterations")
    rec = {k: summary.get(k) for k in keep}
    rec["hinges"] = [{k: h.get(k) for k in ("angle_deg", "s_m", "section_damage", "mechanism",
                                            "opening_face", "rotation_step_mrad",
                                            "rotation_step_mrad_width", "width_damage_min",
                                            "width_damage_max", "width_fraction_damaged")
                      if k in h} for h in summary["hinges"]]
    if "vault" in summary:
        v = summary["vault"]
        rec.update(width_m=v["width_m"], n_width=v["n_width"], ends=v["ends"],
                   failure_load_total_kN=v["failure_load_total_kN"])
    rec["cells"] = summary.get("mesh", {}).get("cells")
    rec["section_damage"] = summary["failure_section_damage"]
    return rec


def rotation_at(summary, sections):
    """3-D: the rotation jump in the collapse step (mrad) across +- one hinge separation at the
    given sections (the 2-D hinges: same grid at the same h), as the stepper measures hinges."""
    dphi = np.asarray(summary["vault"]["failure_section_rotation_step_mrad"])
    b = summary["bridge"]
    rc = 0.5 * (b["r_in"] + b["r_out"])
    d = max(1, int(round(summary["hinge_definition"]["min_separation_m"]
                         / (rc * np.pi / b["n_theta"]))))
    n = dphi.size - 1
    return [round(float(dphi[min(j + d, n)] - dphi[max(j - d, 0)]), 4) for j in sections]


def plot_sections(records, path, h_mesh):
    from damage_dolfinx.viz import figstyle
    pyplot = figstyle.pyplot_styled()
    fig, ax = pyplot.subplots(figsize=(7.2, 3.8))
    for case, rec in records.items():
        D = np.asarray(rec["section_damage"])
        line, = ax.plot(np.linspace(0, 180, D.size), D, lw=1.1,
                        label=f"{CASES[case][2]}: {rec['failure_load_kN']:.4g} kN/m")
        for h in rec["hinges"]:
            if h["mechanism"]:
                ax.plot(h["angle_deg"], h["section_damage"], "v", ms=6, color=line.get_color())
    ax.set_xlabel("angle from the left springing [deg]")
    ax.set_ylabel("$D_j$ at collapse")
    ax.set_ylim(0, 1.45)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper center", fontsize=7, ncol=2)
    figstyle.save(fig, path, title=f"Section damage at collapse, h = {h_mesh} (triangles: "
                                   "hinges rotating at collapse)")


def write_md(result, path):
    lines = [f"# Barrel vault (2.1-ex3-vault) against the 2-D arch, h = {result['h']}", "",
             "| case | cells | failure load [kN/m] | step | rotating hinges (angle, opening face) "
             "| wall [s] |", "|---|---|---|---|---|---|"]
    for case, r in result["cases"].items():
        hinges = ", ".join(f"{h['angle_deg']:.0f}° {h['opening_face']}" for h in r["hinges"]
                           if h["mechanism"])
        lines.append(f"| {CASES[case][2]} | {r['cells']} | {r['failure_load_kN']} | "
                     f"{r['failure_step']} | {hinges} | {r['wall_time_s']:.1f} |")
    rot = {c: r["rotation_at_2d_hinges"] for c, r in result["cases"].items()
           if "rotation_at_2d_hinges" in r}
    if rot:
        first = next(iter(rot.values()))
        lines += ["", "Rotation in the collapse step [mrad] at the sections where the 2-D arch "
                  "hinges (jump of the width-averaged section rotation across +- one ring "
                  "thickness)", "",
                  "| case | " + " | ".join(f"{a:.0f}°" for a in first["angle_deg"]) + " |",
                  "|---|" + "---|" * len(first["angle_deg"]),
                  "| 2-D arch | " + " | ".join(f"{v:+.3f}" for v in first["mrad_2d"]) + " |"]
        for c, r in rot.items():
            lines.append(f"| {CASES[c][2]} | " + " | ".join(f"{v:+.3f}" for v in r["mrad"]) + " |")
    if result.get("stiffness"):
        lines += ["", "Self weight, u_y of the load strip: 3-D / 2-D (exact: thin ~1, plane strain "
                  "1 - nu^2)", "", "| nu | h | u_2d [mm] | thin (W = 0.05) | plane strain | "
                  "1 - nu^2 |", "|---|---|---|---|---|---|"]
        for s in result["stiffness"]:
            lines.append(f"| {s['nu']} | {s['h']} | {s['u_2d_mm']:.4f} | {s['thin_ratio']:.3f} | "
                         f"{s['plane_strain_ratio']:.3f} | {s['plane_strain_exact']:.3f} |")
    Path(path).write_text("\n".join(lines) + "\n")


def main():
    args = parse()
    comm = MPI.COMM_WORLD
    out, ref = Path(args.out), Path(args.ref)
    start = time.perf_counter()
    summaries = {}
    for case in args.cases:
        if not args.plot_only:
            run_case(case, args.h, out, comm)
        summaries[case] = json.loads((out / case / "summary.json").read_text())
    stiff = None if args.no_stiffness or args.plot_only else stiffness(comm)
    if comm.rank != 0:
        return
    from damage_dolfinx.viz import hinge_lines
    ref.mkdir(parents=True, exist_ok=True)
    cases = {c: case_record(s) for c, s in summaries.items()}
    if "arch2d" in summaries:  # do the 3-D cases rotate where the 2-D arch hinges?
        hinges2d = [h for h in summaries["arch2d"]["hinges"] if h["mechanism"]]
        for c, s in summaries.items():
            if "vault" in s and s["vault"]["failure_section_rotation_step_mrad"] is not None \
                    and s["bridge"]["n_theta"] == summaries["arch2d"]["bridge"]["n_theta"]:
                cases[c]["rotation_at_2d_hinges"] = {
                    "angle_deg": [h["angle_deg"] for h in hinges2d],
                    "mrad": rotation_at(s, [h["section"] for h in hinges2d]),
                    "mrad_2d": [h["rotation_step_mrad"] for h in hinges2d]}
    result = {"h": args.h, "cases": cases,
              "stiffness": stiff, "benchmark_wall_s": time.perf_counter() - start,
              "ranks": comm.size}
    if stiff is None and (ref / "vault_3d.json").exists():  # --plot-only keeps the old check
        result["stiffness"] = json.loads((ref / "vault_3d.json").read_text()).get("stiffness")
    (ref / "vault_3d.json").write_text(json.dumps(result, indent=1))
    write_md(result, ref / "vault_3d.md")
    if "vault" in summaries:
        s = summaries["vault"]
        if s.get("failure_load_kN") is not None:
            hinge_lines.plot_hinge_lines(
                s, ref / "hinge_lines.png",
                title=f"2.1-ex3-vault at collapse (P = {s['failure_load_kN']:.4g} kN/m, W = "
                      f"{s['vault']['width_m']:g} m): hinge lines")
        for name in ("vault_slices.png", "load_history.png"):
            if (out / "vault" / name).exists():
                shutil.copy(out / "vault" / name, ref / name)
    first, *rest = list(summaries)
    reference = [(out / c / "history.csv", summaries[c].get("failure_load_kN"), CASES[c][2])
                 for c in rest]
    _plot_curves(out / first / "history.csv", summaries[first].get("failure_load_kN"),
                 CASES[first][2], reference, ref / "load_displacement.png", args.h)
    plot_sections(result["cases"], ref / "section_damage.png", args.h)
    print((ref / "vault_3d.md").read_text())


def _plot_curves(first_csv, first_fail, first_label, others, path, h_mesh):
    """All cases on one load-displacement plot (hinge_lines.plot_load_displacement, extended)."""
    from damage_dolfinx.viz import figstyle
    from damage_dolfinx.viz.hinge_lines import read_curve
    pyplot = figstyle.pyplot_styled()
    fig, ax = pyplot.subplots(figsize=(6.8, 4.4))
    for csv_path, fail, label in [(first_csv, first_fail, first_label)] + others:
        P, d = read_curve(csv_path)
        line, = ax.plot(d, P, "o-", ms=2.5, lw=1.1, label=label)
        if fail is not None:
            ax.plot(d[-1], P[-1], "*", ms=11, color=line.get_color(),
                    label=f"  collapse {fail:.4g} kN/m")
    ax.set_xlabel("downward displacement of the load patch / strip [mm]")
    ax.set_ylabel("line load $P$ [kN per m of width]")
    ax.set_xlim(left=0)
    ax.set_ylim(bottom=0)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="lower right", fontsize=7, ncol=2)
    figstyle.save(fig, path, title=f"Arch (2-D) and barrel vault (3-D): load-displacement, "
                                   f"h = {h_mesh}")


if __name__ == "__main__":
    main()
