"""Section 3.3 Example 3 (thesis Figures 3.19-3.22): viscoelastic ring wrench on a stiff
hexagonal screw (G35 geometry), cyclic pressure on the end of the handle.

    [mpirun -n 2] .venv/bin/python benchmarks/studies/wrench_3_3.py                      # h = 0.3, T = 0.5
    [mpirun -n 2] .venv/bin/python benchmarks/studies/wrench_3_3.py --h 0.15 --T 6.5     # thesis setting

The time step is 0.8 k_max or below (stability.py on the chosen mesh) and divides T, unless --k
is given. Reports the maximal interpenetration (u.nu)_+ between wrench and screw over the run
(value, time, location on the hexagon) and at T, compared with the largest displacement, and
the von Mises and damage extremes at T. Writes under --out (default results/wrench_3_3): the run
folder run/ (history.csv has penetration_max and its location per step; figures 3.19-3.22 of
the catalogue), figure_3_20_mesh.png (deformed wire mesh x2 over the initial outline),
penetration.png (max interpenetration vs t) and wrench.json.
"""
import argparse
import csv
import json
import math
from pathlib import Path

import numpy as np
from mpi4py import MPI

from damage_dolfinx.catalogue import examples
from damage_dolfinx.viz import post
from damage_dolfinx.runtime import runner

EXAMPLE = "3.3-ex3"

parser = argparse.ArgumentParser()
parser.add_argument("--h", type=float, default=0.3, help="element size (thesis reading 0.15, G35)")
parser.add_argument("--k", type=float, help="time step (default: <= 0.8 k_max dividing T)")
parser.add_argument("--T", type=float, default=0.5, help="final time (thesis 6.5)")
parser.add_argument("--elastic-term", default="explicit", choices=["explicit", "implicit"],
                    help="implicit = G33 deviation (fast, not the thesis scheme)")
parser.add_argument("--amplification", type=float, default=2.0, help="Figure 3.20 factor")
parser.add_argument("--out", default="results/wrench_3_3")
args = parser.parse_args()
comm = MPI.COMM_WORLD
out = Path(args.out)


def default_k(h, T):
    """The largest k = T/N <= 0.8 k_max (stability.py on the mesh of size h)."""
    from damage_dolfinx.numerics.stability import SAFETY
    from damage_dolfinx.numerics.stability_bound import exact_estimates
    with exact_estimates():
        probe = examples.get(EXAMPLE).build(comm, h=h, k=T / 1e6, T=T)
    k_max = probe.stability["k_max"]
    return T / math.ceil(T / (SAFETY * k_max)), k_max


def plot_deformed_mesh(stepper, amplification, path):
    """Deformed wire mesh x amplification over the undeformed outline (Figure 3.20, drawn by
    figstyle, the factor rounded to 1-2-5 x 10^k if it is not); collective."""
    from damage_dolfinx.viz import figstyle
    amplification = figstyle.drawn_amplification(amplification)
    deformed = post.gather_cells(stepper.u, stepper.zeta, amplification)
    initial = post.gather_cells(None, stepper.zeta, 0.0)
    if comm.rank != 0:
        return
    panel = {"xy": deformed[0], "values": deformed[1], "name": "zeta", "label": "",
             "title": "deformed mesh, undeformed outline dashed"}
    figstyle.render_fields([panel], path, title=f"Example 3.3-3 at t = {stepper.t:.4g}",
                           amplification=amplification, ref_xy=initial[0], mesh_only=True)


def plot_penetration(history, path):
    from damage_dolfinx.viz import figstyle
    pyplot = figstyle.pyplot_styled()
    with open(history) as f:
        rows = list(csv.DictReader(f))
    t = [float(r["t"]) for r in rows]
    fig, ax = pyplot.subplots(figsize=(6.4, 3.2))
    ax.plot(t, [float(r["penetration_max"]) for r in rows], lw=1.0)
    ax.set_xlabel("$t$ [s]")
    ax.set_ylabel("max $(u \\cdot \\nu)_+$ on $\\Gamma_C$ [m]")
    ax.grid(True, alpha=0.3)
    figstyle.save(fig, path, title="Example 3.3-3: largest interpenetration wrench / screw")


k_max = None
k = args.k
if k is None:
    k, k_max = default_k(args.h, args.T)
summary = runner.run(EXAMPLE, out / "run", h=args.h, k=k, T=args.T,
                     overrides={"elastic_term": args.elastic_term}, progress=True, comm=comm)

# the final state again, for the wire-mesh figure (fields_final.npz holds the P1 fields)
stepper = examples.get(EXAMPLE).build(comm, h=args.h, k=k, T=args.T,
                                      overrides={"stability_check": "off"})
final = np.load(out / "run" / "fields_final.npz") if comm.rank == 0 else None
coords = comm.bcast(final["u_coords"] if final is not None else None, root=0)
values = comm.bcast(final["u"] if final is not None else None, root=0)
X = stepper.u.function_space.tabulate_dof_coordinates()[:, :2]
key = lambda c: np.round(c[:, 0], 9) + 1j * np.round(c[:, 1], 9)  # noqa: E731 (sorts by x1, x2)
order = np.argsort(key(coords))
stepper.u.x.array[:] = values[order[np.searchsorted(key(coords)[order], key(X))]].reshape(-1)
stepper.t = summary["t_final"]
plot_deformed_mesh(stepper, args.amplification, out / "figure_3_20_mesh.png")

if comm.rank == 0:
    plot_penetration(out / "run" / "history.csv", out / "penetration.png")
    u_max = float(np.max(np.linalg.norm(final["u"], axis=1)))
    result = {
        "h": args.h, "k": k, "k_max": summary.get("k_max") or k_max, "T": args.T,
        "elastic_term": args.elastic_term, "status": summary["status"],
        "steps": summary["steps_done"], "wall_time_s": summary["wall_time_s"],
        "mpi_size": comm.size, "mesh": summary["mesh"],
        "max_penetration": summary["max_penetration"],
        "max_penetration_t": summary["max_penetration_t"],
        "max_penetration_at": summary["max_penetration_at"],
        "penetration_at_T": summary["final"]["penetration_max"],
        "u_max_at_T": u_max, "zeta_min_at_T": summary["final"]["zeta_min"],
        "von_mises_max_at_T": float(np.max(final["von_mises"])),
        "von_mises_argmax_at_T": final["von_mises_coords"][int(np.argmax(final["von_mises"]))].tolist(),
        "zeta_argmin_at_T": final["zeta_coords"][int(np.argmin(final["zeta"]))].tolist()}
    (out / "wrench.json").write_text(json.dumps(result, indent=2))
    print(f"h = {args.h}, k = {k:.4g} (k_max = {result['k_max']:.4g}), {result['steps']} steps, "
          f"{result['wall_time_s']:.0f} s on {comm.size} rank(s)")
    print(f"max interpenetration {result['max_penetration']:.3e} m at t = "
          f"{result['max_penetration_t']:.4g}, x = {result['max_penetration_at']}; at T: "
          f"{result['penetration_at_T']:.3e} m; max |u| at T {u_max:.3e} m")
    print(f"at T: max von Mises {result['von_mises_max_at_T']:.4g} Pa at "
          f"{result['von_mises_argmax_at_T']}, min zeta {result['zeta_min_at_T']:.5f} at "
          f"{result['zeta_argmin_at_T']}")
