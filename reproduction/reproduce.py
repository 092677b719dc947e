"""One-command reproduction of the thesis figures (``make figures``) and convergence tables
(``make convergence``): the list of runs, how to launch them, and the index of what they wrote.

Every figure run is one ``damage-dolfinx run`` (under ``mpirun -n NP``) of a catalogue example;
its PNG files, already named after the thesis figures, are copied into the figures folder with
the run's variant appended where an example has several (e.g. 2.4-ex1 Tresca / Coulomb).
``index.json`` there records, per figure, the example, variant, command, status and wall time;
the report (report.py) is built from it. A failed run is recorded and the others go on.

Quick mode: coarse meshes (n / 4, 2h) at the thesis time steps, minutes in total. Full mode: the
catalogue defaults, i.e. the thesis resolutions (or the documented G-defaults).

Resume (``--resume``, ``make figures RESUME=1``): an interrupted reproduction is started again
into the same folder; runs and studies that completed are kept, an interrupted figure run goes on
from its last checkpoint. ``wall_time_s`` in index.json is then the sum over all invocations.
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from damage_dolfinx.viz import figstyle
from reproduction import CHECKOUT
from damage_dolfinx.runtime.atomic import strict_json

#: variants of an example that the thesis draws separately: suffix -> parameter overrides
VARIANTS = {
    "2.4-ex1": {"tresca": {"friction_law": "tresca"}, "coulomb": {"friction_law": "coulomb"}},
    "3.1-ex3": {"undamaged": {"damage_active": "0"}, "damaged": {"damage_active": "1"}},
    "3.3-ex2": {"a": {"initial_damage": "a"}, "b": {"initial_damage": "b"}},
}

#: thesis figure of each convergence study (example id, variant) -> file stem
CONVERGENCE_FIGURES = {
    ("2.1-ex1", ""): "figure_2_2", ("2.2-ex2", ""): "figure_2_11", ("2.3-ex1", ""): "figure_2_15",
    ("2.4-ex1", "tresca"): "figure_2_23_left", ("2.4-ex1", "coulomb"): "figure_2_23_right",
    ("3.1-ex1", ""): "figure_3_2", ("3.2-ex1", ""): "table_3_2_plot", ("3.3-ex1", ""): "figure_3_16",
}

#: same physics as 2.2-ex1, only a convergence table
SKIP_RUN = {"2.2-ex2"}
#: small meshes with very many steps: one rank is faster (measured: 1.7 vs 8 ms per step)
SERIAL = {"3.3-ex2", "3.3-ex3"}


@dataclass
class Job:
    example: str
    variant: str = ""
    options: list = field(default_factory=list)  # CLI options (--n, --k, --h, --set ...)

    @property
    def name(self) -> str:
        return self.example + (f"-{self.variant}" if self.variant else "")


#: quick mode: larger time steps where the scheme allows them (quasistatic, below 2/m_visc)
#: and, for the inertia-limited 3.3 examples, a stable k of the coarse mesh (0.7 k_max) and a
#: shorter wrench run
QUICK_EXTRA = {"2.2-ex3": ["--k", "0.01"], "2.4-ex1": ["--k", "0.01"], "2.4-ex2": ["--k", "0.01"],
               "3.3-ex2": ["--k", "2.5e-4"], "3.3-ex3": ["--k", "2e-5", "--T", "0.5"]}


#: quick-mode n where n / 4 is not a valid mesh of the geometry (the cube with its cavity needs
#: n a multiple of 5)
QUICK_N = {"2.1-ex1-3d": 5}


def _quick_options(ex) -> list:
    """Coarse mesh (n / 4, at least 4, or QUICK_N; or 2 h) at the thesis time step unless
    QUICK_EXTRA."""
    extra = QUICK_EXTRA.get(ex.id, [])
    if ex.n is not None:
        return ["--n", str(QUICK_N.get(ex.id, max(4, ex.n // 4)))] + extra
    if ex.h is not None:
        return ["--h", f"{2 * ex.h:g}"] + extra
    return extra


def _reading_options(reading) -> list:
    """``--reading NAME``, or nothing for each example's default reading."""
    return ["--reading", reading] if reading else []


def figure_jobs(mode: str, reading=None) -> list:
    """One Job per (example, variant) of the catalogue."""
    from damage_dolfinx.catalogue import examples
    jobs = []
    for ex in examples.catalogue().values():
        if ex.id in SKIP_RUN or not ex.figures:
            continue
        base = (_quick_options(ex) if mode == "quick" else []) + _reading_options(reading)
        jobs += _variant_jobs(ex.id, base)
    return jobs


def _variant_jobs(example_id: str, base: list) -> list:
    """One Job per variant of an example (its ``--set`` options after the common ``base``)."""
    jobs = []
    for variant, sets in (VARIANTS.get(example_id) or {"": {}}).items():
        options = list(base)
        for key, value in sets.items():
            options += ["--set", f"{key}={value}"]
        jobs.append(Job(example_id, variant, options))
    return jobs


def convergence_jobs(mode: str, reading=None) -> list:
    """One Job per convergence study (variants of 2.4-ex1: both friction laws)."""
    from damage_dolfinx.catalogue import examples
    jobs = []
    for ex in examples.catalogue().values():
        if not ex.convergence:
            continue
        if mode == "quick":
            ns = sorted(ex.convergence["n"])[:3]
            ks = sorted(ex.convergence["k"], reverse=True)[:3]
            ref_k = min(ks) / 2
            base = ["--ref-n", str(4 * ns[1]), "--ref-k", f"{ref_k:g}",
                    "--n", *map(str, ns), "--k", *(f"{k:g}" for k in ks)]
        else:
            base = []
        base += _reading_options(reading)
        jobs += _variant_jobs(ex.id, base)
    return jobs


def _launch(command: list, np_: int, log: Path) -> tuple:
    """Run the CLI command (under mpirun if np_ > 1); returns (returncode, wall seconds, argv)."""
    argv = [sys.executable, "-m", "damage_dolfinx.cli", *command]
    if np_ > 1:
        argv = ["mpirun", "-n", str(np_), *argv]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1", MPLBACKEND="Agg")
    start = time.perf_counter()
    with open(log, "w") as f:
        code = subprocess.call(argv, stdout=f, stderr=subprocess.STDOUT, env=env)
    return code, time.perf_counter() - start, argv


#: one file per thesis figure where the variants of one example are different thesis figures
VARIANT_FIGURES = {
    ("2.4-ex1", "tresca", "figure_2_24_25.png"): "figure_2_24.png",
    ("2.4-ex1", "coulomb", "figure_2_24_25.png"): "figure_2_25.png",
    ("3.3-ex2", "a", "figure_3_17_18.png"): "figure_3_17.png",
    ("3.3-ex2", "b", "figure_3_17_18.png"): "figure_3_18.png",
}


def _figure_name(file: str, job: Job) -> str:
    """Thesis figures keep their number (plus the variant); other PNGs get the example id."""
    if (job.example, job.variant, file) in VARIANT_FIGURES:
        return VARIANT_FIGURES[(job.example, job.variant, file)]
    stem = Path(file).stem
    if not stem.startswith("figure_"):
        stem = f"{job.example}_{stem}"
    return stem + (f"_{job.variant}" if job.variant else "") + ".png"


def _display(command: list, np_: int) -> str:
    """The command as a user types it."""
    return (f"mpirun -n {np_} " if np_ > 1 else "") + "damage-dolfinx " + " ".join(command)


def _previous_entries(out: Path, key: str, mode: str) -> dict:
    """Successful entries of an earlier ``out/index.json`` (same mode), by job name."""
    try:
        old = json.loads((out / "index.json").read_text())
    except (OSError, ValueError):
        return {}
    if old.get("mode") != mode:
        return {}
    return {e["example"] + (f"-{e['variant']}" if e["variant"] else ""): e
            for e in old.get(key, []) if e.get("returncode") == 0}


def _finish(index: dict, key: str, start: float):
    """Total wall time: this invocation, and the sum over all runs (resumed ones included)."""
    index["wall_time_this_invocation_s"] = round(time.perf_counter() - start, 1)
    index["wall_time_s"] = round(sum(e["wall_time_s"] for e in index[key]), 1)


def run_figures(mode: str, out: Path, np_: int = 2, only=None, resume=False, reading=None) -> dict:
    """Run every figure job, copy the PNGs into ``out`` and write ``out/index.json``. With
    ``resume``, jobs that completed in an earlier invocation (same mode) are kept, not rerun.

    Two lanes: the SERIAL jobs (the wrench, 3.3-ex2: long serial loops) run one
    after the other on one rank, while the other jobs run beside them on np_ - 1 ranks, and on
    np_ ranks once the serial lane is done. index.json lists the runs in catalogue order."""
    import threading
    out.mkdir(parents=True, exist_ok=True)
    runs = out / "runs"
    done = _previous_entries(out, "runs", mode) if resume else {}
    old_figures = json.loads((out / "index.json").read_text())["figures"] if done else []
    index = {"mode": mode, "mpi_size": np_, "runs": [], "figures": []}
    start = time.perf_counter()
    jobs = [job for job in figure_jobs(mode, reading) if not only or job.example in only]
    results, lock = {}, threading.Lock()  # job name -> (entry, figures)

    def write_index():
        with lock:
            entries = [results[j.name] for j in jobs if j.name in results]
            index["runs"] = [e for e, _ in entries]
            index["figures"] = [f for _, figs in entries for f in figs]
            (out / "index.json").write_text(strict_json(index))

    def run_job(job, ranks):
        if job.name in done:
            figs = [f for f in old_figures if f["example"] == job.example
                    and f["variant"] == job.variant]
            with lock:
                results[job.name] = (done[job.name], figs)
            print(f"[figures] {job.name}: done earlier ({done[job.name]['wall_time_s']} s)")
            return
        results[job.name] = _figure_run(job, ranks, runs, out, resume)
        print(f"[figures] {job.name}: exit {results[job.name][0]['returncode']}, "
              f"{results[job.name][0]['wall_time_s']:.1f} s", flush=True)
        write_index()

    serial = [job for job in jobs if job.example in SERIAL]
    lane = threading.Thread(target=lambda: [run_job(job, 1) for job in serial])
    two_lanes = np_ > 1 and bool(serial)
    if two_lanes:
        lane.start()
    for job in jobs:
        if job.example in SERIAL and two_lanes:
            continue
        ranks = 1 if job.example in SERIAL else \
            (max(1, np_ - 1) if two_lanes and lane.is_alive() else np_)
        run_job(job, ranks)
    if two_lanes:
        lane.join()
    write_index()
    if (not only or "2.1-ex3" in only) and "2.1-ex3-force-displacement" not in done:
        _bridge_force_displacement(mode, out, np_, index)
    elif "2.1-ex3-force-displacement" in done:
        index["runs"].append(done["2.1-ex3-force-displacement"])
        index["figures"] += [f for f in old_figures if f["file"] == "figure_2_7.png"]
    _finish(index, "runs", start)
    (out / "index.json").write_text(strict_json(index))
    return index


def _figure_run(job, ranks, runs, out, resume) -> tuple:
    """One figure job: (its index entry, the figures it copied into ``out``)."""
    run_dir = runs / job.name
    # an interrupted run of an earlier invocation goes on from its last checkpoint
    restart = resume and (run_dir / "checkpoint.json").is_file()
    if run_dir.exists() and not restart:
        shutil.rmtree(run_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    command = ["run", job.example, *job.options, "--quiet", "--out", str(run_dir),
               *(["--restart"] if restart else [])]
    # the log beside the run folder: the run folder holds only what the run writes (manifest)
    code, wall, _ = _launch(command, ranks, runs / f"{job.name}.log.txt")
    entry = {"example": job.example, "variant": job.variant, "command": _display(command, ranks),
             "returncode": code, "wall_time_s": round(wall, 2), "folder": str(run_dir)}
    figures = []
    summary = run_dir / "summary.json"
    if summary.is_file():
        s = json.loads(summary.read_text())
        entry.update(status=s.get("status"), title=s.get("title"),
                     figures=[f["file"] for f in s["outputs"]["figures"]])
        for fig in s["outputs"]["figures"]:
            target = _figure_name(fig["file"], job)
            shutil.copy(run_dir / fig["file"], out / target)
            figures.append({"file": target, "source": fig["file"], "example": job.example,
                            "variant": job.variant, "title": s.get("title"),
                            "command": entry["command"],
                            **{k: fig[k] for k in ("t", "amplification") if k in fig}})
            if "amplification" in fig:  # the factor the figure is drawn with (post.py)
                figures[-1]["amplification"] = figstyle.drawn_amplification(fig["amplification"])
    return entry, figures


def _bridge_force_displacement(mode, out, np_, index):
    """Figure 2.7 (force-displacement curve of the arch) from benchmarks/studies/bridge_collapse.py."""
    script = CHECKOUT / "benchmarks" / "studies" / "bridge_collapse.py"
    if not script.is_file():
        return
    folder = out / "runs" / "bridge_collapse"
    folder.mkdir(parents=True, exist_ok=True)
    options = ["--h", "0.1"] if mode == "quick" else []
    argv = [sys.executable, str(script), *options, "--out", str(folder)]
    if np_ > 1:
        argv = ["mpirun", "-n", str(np_), *argv]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1", MPLBACKEND="Agg")
    start = time.perf_counter()
    with open(folder / "log.txt", "w") as f:
        code = subprocess.call(argv, stdout=f, stderr=subprocess.STDOUT, env=env)
    command = (f"mpirun -n {np_} " if np_ > 1 else "") + \
        f"python benchmarks/studies/bridge_collapse.py {' '.join(options)} --out {folder}"
    index["runs"].append({"example": "2.1-ex3", "variant": "force-displacement",
                          "command": command, "returncode": code,
                          "wall_time_s": round(time.perf_counter() - start, 2), "folder": str(folder)})
    if code == 0 and (folder / "force_displacement.png").is_file():
        shutil.copy(folder / "force_displacement.png", out / "figure_2_7.png")
        index["figures"].append({"file": "figure_2_7.png", "example": "2.1-ex3", "variant": "",
                                 "title": "arch bridge: force-displacement curve",
                                 "command": command})


def run_convergence(mode: str, out: Path, np_: int = 2, only=None, resume=False,
                    reading=None) -> dict:
    """Run every convergence study into ``out/<id>[-variant]`` and write ``out/index.json``.
    With ``resume``, studies that completed in an earlier invocation (same mode) are kept."""
    out.mkdir(parents=True, exist_ok=True)
    done = _previous_entries(out, "studies", mode) if resume else {}
    index = {"mode": mode, "mpi_size": np_, "reading": reading or "default", "studies": []}
    start = time.perf_counter()
    for job in convergence_jobs(mode, reading):
        if only and job.example not in only:
            continue
        if job.name in done:
            index["studies"].append(done[job.name])
            print(f"[convergence] {job.name}: done earlier ({done[job.name]['wall_time_s']} s)")
            continue
        folder = out / job.name
        folder.mkdir(parents=True, exist_ok=True)
        command = ["converge", job.example, *job.options, "--quiet", "--overwrite",
                   "--out", str(folder)]
        code, wall, _ = _launch(command, np_, out / f"{job.name}.log.txt")
        entry = {"example": job.example, "variant": job.variant, "command": _display(command, np_),
                 "returncode": code, "wall_time_s": round(wall, 2), "folder": str(folder)}
        summary = folder / "summary.json"
        if code == 0 and summary.is_file():
            s = json.loads(summary.read_text())
            entry.update(rates=s["rates"], reference_wall_time_s=s["reference"]["wall_time_s"],
                         ref_n=s["ref_n"], ref_k=s["ref_k"])
            stem = CONVERGENCE_FIGURES.get((job.example, job.variant))
            if stem:
                shutil.copy(folder / "convergence.png", out / f"{stem}.png")
                entry["figure"] = f"{stem}.png"
        index["studies"].append(entry)
        print(f"[convergence] {job.name}: exit {code}, {wall:.1f} s", flush=True)
        (out / "index.json").write_text(strict_json(index))
    _finish(index, "studies", start)
    (out / "index.json").write_text(strict_json(index))
    return index


def redraw_settings(mode: str, out: Path) -> list:
    """Redraw the setting figures (kind "mesh") of ``out`` with the current style, without
    repeating the runs: each job's stepper is built (same mesh, time step and final time, so
    the loads are drawn at the same time) and only its setting figures are drawn; returns the
    files redrawn. Serial."""
    import tempfile
    from mpi4py import MPI
    from damage_dolfinx.catalogue import examples
    from damage_dolfinx.runtime.figures import draw_figure
    catalogue = examples.catalogue()
    done = []
    for job in figure_jobs(mode):
        ex = catalogue[job.example]
        meshes = [f for f in ex.figures if f.kind == "mesh"]
        if not meshes:
            continue
        opts = dict(zip(job.options[::2], job.options[1::2]))
        from damage_dolfinx.cli import _overrides  # the command line's own reading of --set
        overrides = _overrides([v for k, v in zip(job.options[::2], job.options[1::2])
                                if k == "--set"])
        stepper = ex.build(MPI.COMM_WORLD, n=int(opts["--n"]) if "--n" in opts else None,
                           k=float(opts["--k"]) if "--k" in opts else None,
                           T=float(opts["--T"]) if "--T" in opts else None,
                           h=float(opts["--h"]) if "--h" in opts else None,
                           overrides=overrides)
        with tempfile.TemporaryDirectory() as tmp:
            for fig in meshes:
                draw_figure(ex, fig, stepper, Path(tmp))
                shutil.copy(Path(tmp) / fig.filename, out / _figure_name(fig.filename, job))
                done.append(_figure_name(fig.filename, job))
    return done
