"""Same numbers on every DOLFINx version: one small run per problem, compared across versions.

    python benchmarks/platforms/cross_version.py run --out DIR          # with this interpreter's DOLFINx
    python benchmarks/platforms/cross_version.py compare DIR_A DIR_B ... [--md FILE]

``run`` executes one small run per thesis problem (2.1 ... 3.3, the bridge and the wrench
included) serially through the CLI and writes ``DIR/cross_version.json``: the DOLFINx, PETSc, UFL
and gmsh versions, every run's summary scalars (summary.json ``final``: ||u||_L2, ||eps(u)||_L2,
min/max/mean zeta, plus the problem's own scalars) and its final fields (``fields_final.npz``).
``compare`` reads several such folders (one per version) and prints, per problem, the largest
relative difference of the scalars between any two versions and, where the meshes coincide
(same vertex coordinates, compared after sorting, so a different vertex numbering does not
matter), the largest relative difference of the nodal fields u, zeta and von Mises.
``platforms/cross-version.sh`` runs it on the three Debian stacks.
"""
from __future__ import annotations

import argparse
import itertools
import json
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from common import rel, sorted_fields  # noqa: E402

#: one small run per problem: (id, CLI options). Coarse meshes, short horizons; each takes
#: seconds. The time steps are the catalogue's (stable) ones or the quick-mode ones.
RUNS = [
    ("2.1-ex1", ["--n", "10", "--k", "0.05"]),
    ("2.1-ex3", ["--h", "0.1", "--T", "0.1"]),
    ("2.2-ex2", ["--n", "8", "--k", "0.02"]),
    ("2.3-ex1", ["--n", "8", "--k", "0.05"]),
    ("2.4-ex1", ["--n", "8", "--k", "0.02"]),
    ("3.1-ex1", ["--n", "8", "--k", "0.01", "--T", "0.5"]),
    ("3.2-ex1", ["--n", "8", "--k", "0.02"]),
    ("3.3-ex1", ["--n", "8", "--k", "0.01", "--T", "0.5"]),
    ("3.3-ex3", ["--h", "0.3", "--k", "2e-5", "--T", "0.002"]),
    # a gmsh-written mesh file (the unit square, tags 1-3) read by each version's own reader path
    ("2.2-ex1", ["--mesh", str(Path(__file__).resolve().parents[2] / "tests" / "data" /
                               "rectangle.msh"), "--k", "0.01", "--T", "0.2"]),
]
SKIP_TOP = {"schema", "example", "title", "section", "status", "parameters", "n", "h", "k", "T",
            "num_steps", "steps_done", "t_final", "mpi_size", "mesh", "assumptions", "outputs",
            "environment", "final", "iterations", "wall_time_s", "timings_s", "reading"}
FIELDS = ("u", "zeta", "von_mises")
#: not compared: wall times, and the positions of an extremum (x, y of the node where min zeta or
#: the largest penetration sits), which move between tied nodes; their values are compared
NOT_COMPARED = re.compile(r"(time_s|_x|_y|_x1|_x2)$")


def _numeric_leaves(obj, prefix=""):
    if isinstance(obj, bool):
        return {}
    if isinstance(obj, (int, float)):
        return {prefix: float(obj)} if np.isfinite(obj) else {}
    if isinstance(obj, dict):
        out = {}
        for k, v in obj.items():
            out.update(_numeric_leaves(v, f"{prefix}.{k}" if prefix else str(k)))
        return out
    return {}


def versions() -> dict:
    import dolfinx
    import ufl
    from petsc4py import PETSc
    out = {"dolfinx": dolfinx.__version__, "ufl": getattr(ufl, "__version__", "?"),
           "petsc": ".".join(map(str, PETSc.Sys.getVersion())), "python": sys.version.split()[0]}
    try:
        import gmsh
        out["gmsh"] = gmsh.__version__
    except Exception:  # noqa: BLE001
        out["gmsh"] = "?"
    return out


def run(out: Path) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    record = {"versions": versions(), "runs": {}}
    env = dict(os.environ, OMP_NUM_THREADS="1", MPLBACKEND="Agg")
    for ex_id, options in RUNS:
        folder = out / ex_id
        shutil.rmtree(folder, ignore_errors=True)  # a fresh run each time
        cmd = [sys.executable, "-m", "damage_dolfinx.cli", "run", ex_id, *options,
               "--out", str(folder), "--quiet"]
        t0 = time.perf_counter()
        proc = subprocess.run(cmd, env=env, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        entry = {"options": options, "exit": proc.returncode, "wall_time_s": round(wall, 2)}
        if proc.returncode == 0:
            summary = json.loads((folder / "summary.json").read_text())
            scalars = _numeric_leaves(summary.get("final", {}), "final")
            for key, value in summary.items():
                if key not in SKIP_TOP:
                    scalars.update(_numeric_leaves(value, key))
            entry.update(scalars=scalars, fields=f"{ex_id}/fields_final.npz",
                         cells=summary["mesh"].get("cells"))
        else:
            entry["error"] = (proc.stderr or proc.stdout).strip().splitlines()[-1:]
        record["runs"][ex_id] = entry
        print(f"{ex_id:8s} exit {proc.returncode} {wall:6.1f} s", flush=True)
    (out / "cross_version.json").write_text(json.dumps(record, indent=1))
    return record


def compare(folders, md=None) -> str:
    records = [json.loads((Path(f) / "cross_version.json").read_text()) for f in folders]
    names = [r["versions"]["dolfinx"] for r in records]
    lines = ["| run | " + " | ".join(f"DOLFINx {n}" for n in names)
             + " | largest rel. diff of the summary scalars | scalar | nodal fields (same mesh?) |",
             "|---|" + "---|" * len(names) + "---|---|---|"]
    for ex_id, _ in RUNS:
        entries = [r["runs"].get(ex_id, {}) for r in records]
        status = [("ok %.0f s" % e["wall_time_s"]) if e.get("exit") == 0 else
                  f"FAILED ({e.get('exit')})" for e in entries]
        worst, worst_key, field_note = 0.0, "", ""
        if all(e.get("exit") == 0 for e in entries):
            for a, b in itertools.combinations(entries, 2):
                for key in sorted(set(a["scalars"]) & set(b["scalars"])):
                    if NOT_COMPARED.search(key):
                        continue
                    va, vb = a["scalars"][key], b["scalars"][key]
                    d = abs(va - vb) / max(abs(va), abs(vb), 1e-300)
                    if d > worst:
                        worst, worst_key = d, key
            fdiffs, same_mesh = [], True
            sorted_all = [sorted_fields(Path(f) / e["fields"], FIELDS) for f, e in zip(folders, entries)]
            for fa, fb in itertools.combinations(sorted_all, 2):
                for name in set(fa) & set(fb):
                    if fa[name][0].shape != fb[name][0].shape or \
                            np.abs(fa[name][0] - fb[name][0]).max() > 1e-8:
                        same_mesh = False
                        continue
                    fdiffs.append(rel(fa[name][1], fb[name][1]))
            cells = {e.get("cells") for e in entries}
            field_note = (f"{max(fdiffs):.1e} (same mesh)" if fdiffs and same_mesh else
                          f"meshes differ (cells {sorted(cells)})")
        lines.append(f"| {ex_id} | " + " | ".join(status) + f" | {worst:.1e} | {worst_key} | {field_note} |")
    header = "Versions: " + "; ".join(
        f"DOLFINx {r['versions']['dolfinx']} (PETSc {r['versions']['petsc']}, UFL {r['versions']['ufl']}, "
        f"gmsh {r['versions']['gmsh']}, Python {r['versions']['python']})" for r in records)
    text = header + "\n\n" + "\n".join(lines) + "\n"
    if md:
        Path(md).write_text(text)
    return text


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run")
    r.add_argument("--out", type=Path, required=True)
    c = sub.add_parser("compare")
    c.add_argument("folders", nargs="+")
    c.add_argument("--md")
    args = ap.parse_args(argv)
    if args.cmd == "run":
        rec = run(args.out)
        sys.exit(0 if all(e["exit"] == 0 for e in rec["runs"].values()) else 1)
    print(compare(args.folders, args.md))


if __name__ == "__main__":
    main()
