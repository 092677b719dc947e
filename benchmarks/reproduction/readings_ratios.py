"""Ratios ours / thesis per cell of a convergence study against a thesis table.

    python benchmarks/reproduction/readings_ratios.py TABLE FOLDER [FOLDER ...] [--column error_v_L2]
                                         [--exclude N,K ...]
    python benchmarks/reproduction/readings_ratios.py --summary

``--summary``: one row per thesis table for the committed thesis-size studies,
reference_output/convergence (default reading) and reference_output/convergence-literal (the
literal reading, where the default differs): the summary table of benchmarks/readings.md.

TABLE is a key of benchmarks/thesis_tables.json (2.4, 2.5, 2.6, 2.7, 3.1, 3.2); each FOLDER holds
a study's errors.csv (damage-dolfinx converge). Prints, per folder, a markdown block: the cells
in common, min / median / max of the ratio, the fitted rates in h + k of the thesis and of ours
over the same cells (least squares in log-log, h + k of our errors.csv), and the ratio table.
``--exclude 32,0.01`` leaves a cell out of the statistics (the Table 3.1 misprint 7.562e-4 between
1.0e-2 and 6.6e-3); it is still shown in the table, in brackets.
Nothing is copied by hand: the numbers of benchmarks/readings.md are this script's output.
"""
import argparse
import csv
import json
from pathlib import Path

import sys

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # benchmarks/: common.py
from common import RECORDS, THESIS_TABLES as TABLES  # noqa: E402


def compare(table: dict, folder: Path, column: str = "error", exclude=()) -> dict:
    rows = list(csv.DictReader(open(folder / "errors.csv")))
    ours = {(int(r["n"]), float(r["k"])): (float(r[column]), float(r["h_plus_k"])) for r in rows}
    cells = [(int(n), k, v, *ours[(int(n), k)]) for n, vals in table["rows"].items()
             for k, v in zip(table["k"], vals) if (int(n), k) in ours]
    shown, cells = cells, [c for c in cells if (c[0], c[1]) not in set(exclude)]
    thesis, mine, hk = (np.array([c[i] for c in cells]) for i in (2, 3, 4))
    ratio = mine / thesis
    rate = lambda e: float(np.polyfit(np.log(hk), np.log(e), 1)[0])  # noqa: E731
    return {"cells": cells, "shown": shown, "excluded": list(exclude), "ratio": ratio, "min": ratio.min(), "median": float(np.median(ratio)),
            "max": ratio.max(), "rate_thesis": rate(thesis), "rate_ours": rate(mine)}


def markdown(name: str, c: dict) -> str:
    ns = sorted({x[0] for x in c["shown"]})
    ks = sorted({x[1] for x in c["shown"]}, reverse=True)
    r = {(x[0], x[1]): x[3] / x[2] for x in c["shown"]}
    fmt = lambda n, k: (f"({r[(n, k)]:.3g})" if (n, k) in c["excluded"]  # noqa: E731
                        else f"{r[(n, k)]:.3g}") if (n, k) in r else "-"
    lines = [f"`{name}`: {len(c['cells'])} cells, ratio ours/thesis min {c['min']:.3g}, median "
             f"{c['median']:.3g}, max {c['max']:.3g}; fitted rate in h + k thesis "
             f"{c['rate_thesis']:.3f}, ours {c['rate_ours']:.3f}", "",
             "| n \\ k | " + " | ".join(f"{k:g}" for k in ks) + " |", "|---|" + "---|" * len(ks)]
    lines += [f"| {n} | " + " | ".join(fmt(n, k) for k in ks) + " |" for n in ns]
    return "\n".join(lines) + "\n"


#: thesis table -> (study folder, cells left out of the statistics)
STUDIES = {"2.4": ("2.2-ex2", []), "2.5": ("2.3-ex1", []), "2.6": ("2.4-ex1-tresca", []),
           "2.7": ("2.4-ex1-coulomb", []), "3.1": ("3.1-ex1", [(32, 0.01)]), "3.2": ("3.2-ex1", [])}


def summary(tables: dict) -> str:
    ref = RECORDS
    lines = ["| thesis table | study | reading | ours / thesis per cell (min / median / max) | "
             "fitted rate thesis / ours |", "|---|---|---|---|---|"]
    for key, (folder, exclude) in STUDIES.items():
        for sub in ("convergence", "convergence-literal"):
            f = ref / sub / folder
            if not (f / "errors.csv").is_file():
                continue
            reading = json.loads((f / "summary.json").read_text()).get("reading") or "literal"
            c = compare(tables[key], f, "error", exclude)
            note = " (n = 32, k = 0.01 misprint left out)" if exclude else ""
            lines.append(f"| {key} | {sub}/{folder} | {reading} | {c['min']:.3g} / "
                         f"{c['median']:.3g} / {c['max']:.3g}{note} | "
                         f"{c['rate_thesis']:.2f} / {c['rate_ours']:.2f} |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    import sys
    if sys.argv[1:] == ["--summary"]:
        print(summary(json.loads(TABLES.read_text())["tables"]))
        sys.exit(0)
    p = argparse.ArgumentParser()
    p.add_argument("table")
    p.add_argument("folders", nargs="+")
    p.add_argument("--column", default="error", help="errors.csv column (default: error)")
    p.add_argument("--exclude", nargs="*", default=[], metavar="N,K",
                   help="cells left out of the statistics, e.g. 32,0.01")
    a = p.parse_args()
    exclude = [(int(c.split(",")[0]), float(c.split(",")[1])) for c in a.exclude]
    table = json.loads(TABLES.read_text())["tables"][a.table]
    for folder in a.folders:
        print(markdown(f"{folder} [{a.column}]", compare(table, Path(folder), a.column, exclude)))
