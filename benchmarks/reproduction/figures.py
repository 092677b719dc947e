"""Regenerate the thesis figures (PNG, named after the thesis figure numbers).

    python benchmarks/reproduction/figures.py [--quick] [--np 2] [--out results/figures] [--only ID ...]

Runs every catalogue example (and its variants) with `damage-dolfinx run` under
`mpirun -n NP`, copies the figures into OUT and writes OUT/index.json (command, status and wall
time of each run). Quick mode: coarse meshes at the thesis time steps; full mode: thesis
resolutions. See reproduction/reproduce.py.

Thesis pairs drawn by different runs or at different times (2.4/2.5, 2.17, 2.20, 2.24/2.25,
3.8) are then re-rendered from their saved panel data on one stress scale (figstyle.render_pair).
"""
import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # benchmarks/: common.py
import common  # noqa: E402,F401  (puts the checkout on sys.path)
from damage_dolfinx.viz import figstyle  # noqa: E402
from reproduction import reproduce  # noqa: E402

#: thesis figures whose files share one stress (or strain) colour scale: the pairs, and the
#: three times of 2.3 Example 3 (at t = 1 the load is gone: its stress is read on the scale of
#: the loaded times, not on its own)
PAIRS = [("figure_2_4.png", "figure_2_5.png"), ("figure_2_17_t0.png", "figure_2_17_t2.png"),
         ("figure_2_20_t0.png", "figure_2_20_t0.5.png", "figure_2_21.png"),
         ("figure_2_24.png", "figure_2_25.png"),
         ("figure_3_8_undamaged.png", "figure_3_8_damaged.png")]


def restyle(out: Path, index: dict) -> int:
    """Re-render every field figure in ``out`` from its saved panel data with the current
    style (scales, colour maps, a readable amplification): no run is repeated."""
    done = 0
    for entry in index["figures"]:
        npz = _npz(out, index, entry)
        if npz and (out / entry["file"]).is_file():
            figstyle.render_saved(npz, out / entry["file"])
            done += 1
    return done


def _guides(npz, file):
    """The guides of one figure (reproduction.figures.guides), with its run's summary."""
    import json
    from reproduction.figures import guides
    summary_path = npz.parent / "summary.json" if npz else None
    summary = (json.loads(summary_path.read_text())
               if summary_path and summary_path.is_file() else None)
    return guides(file, summary)


def draw_guides(out: Path, index: dict) -> int:
    """Re-render the figures that draw something beside the body (the frictional planes, the
    foundations and obstacles, the arch's hinges: reproduction.figures.guides) from their panel
    data; a figure of PAIRS keeps its group's shared scales."""
    from damage_dolfinx.viz.figscales import is_damage, shared_limits
    done = 0
    for entry in index["figures"]:
        npz = _npz(out, index, entry)
        marks = _guides(npz, entry["file"])
        if not (npz and marks):
            continue
        limits = None
        group = next((pair for pair in PAIRS if entry["file"] in pair), None)
        entries = [next((f for f in index["figures"] if f["file"] == name), None)
                   for name in group or ()]
        npzs = [_npz(out, index, e) for e in entries]
        if group and all(npzs):  # the scales share_pair_scales gave the group
            loaded = [figstyle.load_panels(n)[0] for n in npzs]
            limits = {i: shared_limits([p[i]["values"] for p in loaded])
                      for i in range(min(len(p) for p in loaded))
                      if not any(is_damage(p[i]["name"], p[i]["label"]) for p in loaded)}
        figstyle.render_saved(npz, out / entry["file"], limits=limits, guides=marks)
        done += 1
    return done


def share_pair_scales(out: Path, index: dict) -> list:
    """Re-render every group of PAIRS present in ``out`` on shared scales; returns the groups."""
    done = []
    for pair in PAIRS:
        entries = [next((f for f in index["figures"] if f["file"] == name), None) for name in pair]
        npzs = [_npz(out, index, e) for e in entries]
        if all(npzs):
            figstyle.render_shared(npzs, [out / name for name in pair])
            done.append(pair)
    return done


def stamp_settings(out: Path, index: dict, from_runs=True) -> list:
    """Say on each setting figure which mesh it draws when the thesis's caption names another
    (reproduction.figures.mesh_drawn); from the run's own copy (``from_runs``), so that a
    second call does not stamp twice. Returns the files stamped."""
    from damage_dolfinx.catalogue import examples
    from reproduction.figures import THESIS_FIGURES, mesh_drawn
    from reproduction.plots import note_under
    done = []
    for fig in THESIS_FIGURES:
        for file in fig.files:
            entry = next((f for f in index["figures"] if f["file"] == file), None)
            if not entry or not (out / file).is_file():
                continue
            note = mesh_drawn(fig, entry.get("command", ""), examples.get(fig.example).n)
            run = next((r for r in index["runs"] if r["example"] == entry["example"]
                        and r["variant"] == entry["variant"]), None)
            source = Path(run["folder"]) / entry["source"] if run and entry.get("source") else None
            if note and (not from_runs or (source and source.is_file())):
                note_under(out / file, note, source if from_runs else None)
                done.append(file)
    return done


def _npz(out, index, entry):
    if not entry or not entry.get("source"):
        return None
    run = next((r for r in index["runs"] if r["example"] == entry["example"]
                and r["variant"] == entry["variant"]), None)
    npz = Path(run["folder"]) / Path(entry["source"]).with_suffix(".panel.npz") if run else None
    return npz if npz and npz.is_file() else None


p = argparse.ArgumentParser()
p.add_argument("--quick", action="store_true", help="coarse meshes (minutes)")
p.add_argument("--np", type=int, default=2, help="MPI ranks per run")
p.add_argument("--out", default=None)
p.add_argument("--only", nargs="+", help="example ids")
p.add_argument("--restyle", action="store_true",
               help="no runs: re-render the figures of OUT from their panel data (current style)")
p.add_argument("--settings", action="store_true",
               help="no runs: redraw the setting figures of OUT from one time step of each job")
p.add_argument("--resume", action="store_true",
               help="keep the runs that completed in an earlier invocation into the same OUT")
a = p.parse_args()
mode = "quick" if a.quick else "full"
out = Path(a.out or ("results/figures-quick" if a.quick else "results/figures"))
if a.np < 1:
    p.error(f"--np must be a whole number >= 1, got {a.np}")
if out.exists() and not out.is_dir():
    p.error(f"--out {str(out)!r} is a file, not a folder")
if a.only:
    known = {job.example for job in reproduce.figure_jobs(mode, None)}
    unknown = sorted(set(a.only) - known)
    if unknown:
        p.error(f"--only: no figure run of {', '.join(unknown)}; the examples with figures: "
                f"{', '.join(sorted(known))}")
if (a.restyle or a.settings) and not (out / "index.json").is_file():
    p.error(f"--restyle and --settings redraw the figures of an earlier build: {str(out)!r} "
            "holds none (no index.json)")
if a.settings:
    import json
    print(f"redrawn: {' '.join(reproduce.redraw_settings(mode, out))}; meshes named: "
          f"{' '.join(stamp_settings(out, json.loads((out / 'index.json').read_text()), False))}")
if a.restyle:
    import json
    index = json.loads((out / "index.json").read_text())
    print(f"restyled {restyle(out, index)} figures in {out}; shared scales: "
          f"{len(share_pair_scales(out, index))}; with guides: {draw_guides(out, index)}; "
          f"meshes named: {len(stamp_settings(out, index))}")
if a.restyle or a.settings:
    raise SystemExit(0)
index = reproduce.run_figures(mode, out, a.np, a.only, a.resume)
shared = share_pair_scales(out, index)
draw_guides(out, index)
stamp_settings(out, index)
failed = [r for r in index["runs"] if r["returncode"] != 0]
print(f"{len(index['figures'])} figures from {len(index['runs'])} runs in "
      f"{index['wall_time_this_invocation_s']} s (runs: {index['wall_time_s']} s in two lanes) "
      f"({mode} mode, {a.np} ranks) -> {out}; failed runs: {[r['example'] for r in failed] or 'none'}; "
      f"pairs on shared scales: {len(shared)}")
if failed:  # `make figures` fails when a run fails (the index and the report still say which)
    sys.exit(1)
