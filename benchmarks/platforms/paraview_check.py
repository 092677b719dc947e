"""Our XDMF output read by ParaView itself, compared with what the run says it wrote.

    python benchmarks/platforms/paraview_check.py RUN_FOLDER ... --out DIR

For each run folder, ParaView's Python (``pvpython``, Debian package python3-paraview; under
``xvfb-run`` when there is no display) opens ``fields.xdmf`` with ParaView's XDMF reader
(``platforms/pv_read.py``). This script then checks, against the run's own files:

* time steps: every XDMF time is a time of ``history.csv`` (to 1e-12) or a step of the run's time
  grid (a run that writes a history row every few steps), each appears once and in
  increasing order (a restarted run too: ``make check-paraview`` includes one), and the last one
  is the run's ``t_final`` (summary.json);
* arrays at the last time: u and zeta (point data) and von Mises (cell data) equal the gathered
  final fields of ``fields_final.npz``, matched by coordinates (points) and cell centres, to single precision (FLOAT32_EPS below).

It writes ``DIR/paraview_check.md`` (one row per run: time steps, largest relative difference per
array) and ``DIR/<run>.png`` (the frame ParaView rendered: zeta on the deformed body). Exit status
1 when a check fails. ``make check-paraview`` runs it on one small run per problem.
"""
from __future__ import annotations

import argparse
import csv
import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

REPO = Path(__file__).resolve().parents[2]
PV_READ = REPO / "platforms" / "pv_read.py"
#: DOLFINx 0.5.2 writes its HDF5 data items without Precision="8", which XDMF reads as 4-byte
#: floats: ParaView shows our fields (and coordinates) in single precision. Arrays must agree to
#: the float32 machine epsilon 2^-23 relative to the field's largest value.
FLOAT32_EPS = 2.0 ** -23
TOL = FLOAT32_EPS


def _pvpython() -> list:
    exe = shutil.which("pvpython")
    if exe is None:
        raise SystemExit("paraview_check: pvpython not found (apt-get install python3-paraview xvfb)")
    return (["xvfb-run", "-a", exe] if shutil.which("xvfb-run") else [exe])


def _match(coords_seen, values_seen, coords_b, values_b) -> float:
    """Largest |seen - b| / max|b| after matching each row of b to the nearest seen point (the
    coordinates ParaView reads are single precision, see FLOAT32_EPS); inf if a row of b has no
    point within 1e-6 of the body's size."""
    seen_xy = np.asarray(coords_seen, float)[:, :2]
    b_xy = np.asarray(coords_b, float)[:, :2]
    dist, idx = cKDTree(seen_xy).query(b_xy)
    size = np.ptp(b_xy, axis=0).max()
    if dist.max() > 1e-6 * size:
        return float("inf")
    seen = [np.atleast_1d(np.asarray(values_seen[i], float)).ravel() for i in idx]
    diffs = []
    for s_v, v in zip(seen, np.asarray(values_b, float).reshape(len(b_xy), -1)):
        if s_v.size == 9 and v.size == 4:  # XDMF pads a 2 x 2 tensor to 3 x 3
            s_v = s_v.reshape(3, 3)[:2, :2].ravel()
        diffs.append(np.abs(s_v[:v.size] - v).max())  # and a 2-D vector to 3-D
    return float(max(diffs) / max(np.abs(values_b).max(), 1e-300))


def check(folder: Path, out: Path) -> dict:
    name = folder.name
    seen_json = out / f"{name}.json"
    frame = out / f"{name}.png"
    for _attempt in range(2):  # xvfb-run -a can lose a race for its display number once
        proc = subprocess.run([*_pvpython(), str(PV_READ), str(folder), str(seen_json), str(frame)],
                              capture_output=True, text=True)
        if proc.returncode == 0:
            break
    if proc.returncode != 0:
        return {"run": name, "ok": False, "error": proc.stderr.strip().splitlines()[-1:]}
    seen = json.loads(seen_json.read_text())
    summary = json.loads((folder / "summary.json").read_text())
    with open(folder / "history.csv") as f:
        hist_t = np.array([float(r["t"]) for r in csv.DictReader(f)])
    times = np.array(seen["times"])
    # a time of the run's grid: a history.csv row, or a step between rows (history_every > 1)
    on_grid = [np.abs(hist_t - t).min() < 1e-12
               or abs(t / summary["k"] - round(t / summary["k"])) < 1e-6 for t in times]
    times_ok = bool(len(times) and all(on_grid)
                    and abs(times[-1] - summary["t_final"]) < 1e-12
                    and np.all(np.diff(times) > 0))  # one series, each time once (restarts)
    final = np.load(folder / "fields_final.npz")
    diffs = {}
    for grid in seen["grids"].values():
        for arr, vals in grid["point_arrays"].items():
            if arr in final.files:
                diffs[arr] = _match(grid["points"], vals, final[arr + "_coords"], final[arr])
        for arr, vals in grid["cell_arrays"].items():
            if arr in final.files:
                diffs[arr] = _match(grid["cell_centres"], vals, final[arr + "_coords"], final[arr])
    ok = times_ok and all(d < TOL for d in diffs.values()) and \
        {"u", "zeta", "von_mises"} <= set(diffs)
    return {"run": name, "ok": ok, "reader": seen["reader"], "xdmf_times": len(times),
            "t_last": float(times[-1]) if len(times) else None, "t_final": summary["t_final"],
            "times_ok": times_ok, "diffs": diffs, "frame": frame.name}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folders", nargs="+", type=Path)
    ap.add_argument("--out", type=Path, required=True)
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    rows = [check(f, args.out) for f in args.folders]
    lines = ["| run | ParaView reader | XDMF time steps | last time = t_final, all in history.csv "
             "| u | zeta | von Mises | frame |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "error" in r:
            lines.append(f"| {r['run']} | FAILED: {r['error']} | | | | | | |")
            continue
        d = r["diffs"]
        fmt = lambda k: f"{d[k]:.1e}" if k in d else "missing"  # noqa: E731
        lines.append(f"| {r['run']} | {r['reader']} | {r['xdmf_times']} | "
                     f"{'yes' if r['times_ok'] else 'NO'} (t = {r['t_last']:g}) | {fmt('u')} | "
                     f"{fmt('zeta')} | {fmt('von_mises')} | [{r['frame']}]({r['frame']}) |")
    text = ("ParaView (pvpython) reading our fields.xdmf: largest difference from fields_final.npz, "
            "relative to the field's largest value, at the last time step.\n\n" + "\n".join(lines) + "\n")
    (args.out / "paraview_check.md").write_text(text)
    (args.out / "paraview_check.json").write_text(json.dumps(rows, indent=1))
    print(text)
    sys.exit(0 if all(r["ok"] for r in rows) else 1)


if __name__ == "__main__":
    main()
