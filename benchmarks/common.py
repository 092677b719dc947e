"""Helpers shared by the benchmark scripts (each script puts this folder on ``sys.path`` and
imports it; importing it puts the checkout on ``sys.path`` too, so that the scripts import the
checkout's ``reproduction`` package, which is not installed with the library): the checkout's folders, the fastest-of-blocks timing and the per-problem record of
the step profiles (performance/step_floor.py), and the field comparison of the platform checks
(platforms/cross_version.py, platforms/ranks_check.py)."""
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

BENCHMARKS = Path(__file__).resolve().parent
#: the checkout: the folder holding benchmarks/, reproduction/ and damage_dolfinx/
REPO = BENCHMARKS.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))
#: the committed records, one folder per topic (benchmarks/README.md names each)
RECORDS = BENCHMARKS / "reference_output"
#: the thesis error tables (transcribed from the thesis; Tables 2.1 and 3.3 withheld)
THESIS_TABLES = BENCHMARKS / "thesis_tables.json"


def commit() -> str:
    """Short hash of the checkout's HEAD ('unknown' outside git, or where git is not installed)."""
    try:
        out = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"],
                             capture_output=True, text=True)
    except OSError:
        return "unknown"
    return out.stdout.strip() or "unknown"


def best(fn, repeat, blocks=5) -> float:
    """Seconds per call of fn, the fastest of ``blocks`` blocks (robust on a loaded machine)."""
    fastest = float("inf")
    for _ in range(blocks):
        start = time.perf_counter()
        for _ in range(repeat):
            fn()
        fastest = min(fastest, (time.perf_counter() - start) / repeat)
    return fastest


def profile_rows(problems, only, profile) -> list:
    """profile(example) for each problem (those in ``only`` if given), each row printed as JSON
    as soon as it is measured."""
    rows = []
    for example in problems:
        if only and example not in only:
            continue
        rows.append(profile(example))
        print(json.dumps(rows[-1]), flush=True)
    return rows


def write_record(out, stem, rows, lines, **extra):
    """``<out>/<stem>.json`` (extra keys, date, load average, commit, rows) and ``<stem>.md``
    (the table ``lines``, also printed)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{stem}.json").write_text(json.dumps(
        {**extra, "date": time.strftime("%Y-%m-%d"),
         "load_average": [round(x, 2) for x in os.getloadavg()],
         "commit": commit(), "rows": rows}, indent=1))
    (out / f"{stem}.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


def sorted_fields(path, names) -> dict:
    """The nodal fields ``names`` of a fields_final.npz, each with its coordinates, in the order
    of their coordinates (so that runs on different partitions or versions compare)."""
    data = np.load(path)
    out = {}
    for name in names:
        if name not in data or name + "_coords" not in data:
            continue
        X = np.round(np.asarray(data[name + "_coords"], float), 10)
        order = np.lexsort(X.T[::-1])
        out[name] = (X[order], np.asarray(data[name]).reshape(len(X), -1)[order])
    return out


def rel(a, b) -> float:
    """Relative l2 difference of a from b."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.linalg.norm(a - b) / max(np.linalg.norm(b), 1e-300))


def md_head(head) -> list:
    """A Markdown table's header and rule lines for the column names ``head``."""
    return [md_row(head), "|" + "---|" * len(head)]


def md_row(cells) -> str:
    """One Markdown table row of ``cells`` (each written with str)."""
    return "| " + " | ".join(str(c) for c in cells) + " |"


#: the environment of a benchmark's runs (mpirun as root and oversubscribed, one thread a rank)
RUN_ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1", OMP_NUM_THREADS="1", MPLBACKEND="Agg")


def timed_run(args, run, ranks=1) -> dict:
    """``python -m damage_dolfinx.cli run ARGS`` from the checkout (ARGS ending in ``--out run``
    or naming it), under ``mpirun -n ranks`` when ranks > 1, each rank under GNU time where
    /usr/bin/time is installed; raises with the output when it fails. Returns ``cmd`` (the
    command list), ``process_s`` (its wall time), ``summary`` (the run's summary.json),
    ``rows`` (its history.csv rows), ``rss_mb`` (peak memory per rank, empty without GNU time)
    and ``cpu_s`` (CPU time of all ranks, nan without GNU time)."""
    import csv
    import re
    timer = (["/usr/bin/time", "-f", "peak_rss_kb=%M cpu_s=%U+%S"]
             if os.path.exists("/usr/bin/time") else [])
    cmd = [*timer, sys.executable, "-m", "damage_dolfinx.cli", "run", *args]
    if ranks > 1:
        cmd = ["mpirun", "-n", str(ranks)] + cmd
    start = time.perf_counter()
    proc = subprocess.run(cmd, cwd=REPO, env=RUN_ENV, capture_output=True, text=True)
    process_s = time.perf_counter() - start
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{proc.stdout}\n{proc.stderr}")
    with open(Path(run) / "history.csv") as f:
        rows = list(csv.DictReader(f))
    cpu = re.findall(r"cpu_s=([\d.]+)\+([\d.]+)", proc.stderr)
    return {"cmd": cmd, "process_s": process_s,
            "summary": json.loads((Path(run) / "summary.json").read_text()), "rows": rows,
            "rss_mb": [int(v) / 1024.0 for v in re.findall(r"peak_rss_kb=(\d+)", proc.stderr)],
            "cpu_s": sum(float(u) + float(s) for u, s in cpu) if timer else float("nan")}
