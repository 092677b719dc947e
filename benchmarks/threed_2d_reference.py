"""Record (or check) fixed small 2-D runs, the guard of issue 17: the 3-D generalisation of the
constitutive forms must leave every 2-D result identical to round-off.

    .venv/bin/python benchmarks/threed_2d_reference.py --record   # writes tests/data/reference_2d.json
    .venv/bin/python benchmarks/threed_2d_reference.py            # compares a fresh run with it

The reference in tests/data/reference_2d.json was recorded at commit 549c1d6 (before any
issue-17 change); tests/test_3d.py::test_2d_runs_unchanged repeats the comparison.
"""
from __future__ import annotations

import argparse
import csv
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = ROOT / "tests" / "data" / "reference_2d.json"
#: structured meshes only (a gmsh mesh may differ between gmsh versions of the CI stacks)
CASES = {"2.1-ex1": ["--n", "10", "--k", "0.05"],                 # variant B: split, plane-stress B
         "2.2-ex1": ["--n", "8", "--k", "0.02", "--T", "0.2"]}    # Phi_L(B eps), Tresca
COLUMNS = ("u_L2", "eps_u_L2", "zeta_min", "zeta_max", "zeta_mean")
FIELDS = ("u", "zeta", "von_mises")


def run_case(example_id, args, out: Path) -> dict:
    """History scalars and final fields of one run (same keys as the reference)."""
    cmd = [sys.executable, "-m", "damage_dolfinx.cli", "run", example_id, *args,
           "--no-figures", "--quiet", "--checkpoint-seconds", "0", "--out", str(out)]
    subprocess.run(cmd, check=True, cwd=ROOT, capture_output=True)
    with open(out / "history.csv") as f:
        rows = list(csv.DictReader(f))
    fields = np.load(out / "fields_final.npz")
    return {"args": args,
            "history": {c: [float(r[c]) for r in rows] for c in COLUMNS},
            "fields": {name: fields[name].ravel().tolist() for name in FIELDS},
            "coords": {name: fields[name + "_coords"].ravel().tolist() for name in FIELDS}}


def compare(new: dict, ref: dict) -> dict:
    """Largest relative differences: history scalars (per value, relative to max(|ref|, 1e-300))
    and final fields (norm-wise); coordinates must agree to 1e-12 (same mesh, same order)."""
    out = {}
    for name in FIELDS:
        if not np.allclose(new["coords"][name], ref["coords"][name], atol=1e-12):
            raise AssertionError(f"{name}: different dof coordinates (mesh or ordering changed)")
        a, b = np.asarray(new["fields"][name]), np.asarray(ref["fields"][name])
        out[f"field_{name}"] = float(np.linalg.norm(a - b) / max(np.linalg.norm(b), 1e-300))
    for c in COLUMNS:
        a, b = np.asarray(new["history"][c]), np.asarray(ref["history"][c])
        if a.shape != b.shape:
            raise AssertionError(f"{c}: {a.size} steps instead of {b.size}")
        out[f"history_{c}"] = float(np.max(np.abs(a - b) / np.maximum(np.abs(b), 1e-300)))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--record", action="store_true", help="write the reference file")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        runs = {ex: run_case(ex, a, Path(tmp) / ex) for ex, a in CASES.items()}
    if args.record:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, text=True,
                                capture_output=True).stdout.strip()
        REFERENCE.parent.mkdir(exist_ok=True)
        REFERENCE.write_text(json.dumps({"commit": commit, "runs": runs}) + "\n")
        print(f"recorded {', '.join(runs)} at {commit} -> {REFERENCE}")
        return
    ref = json.loads(REFERENCE.read_text())
    for ex, run in runs.items():
        diffs = compare(run, ref["runs"][ex])
        print(f"{ex} vs {ref['commit']}: largest relative difference {max(diffs.values()):.2e}")
        for key, value in diffs.items():
            print(f"    {key:22s} {value:.2e}")


if __name__ == "__main__":
    main()
