"""Record (or check) fixed small 2-D runs, the guard of the 3-D extension: the 3-D generalisation of the
models must leave every 2-D result identical to round-off, for every problem (Sections 2.1-3.3).

    .venv/bin/python tests/reference_2d.py --record   # writes tests/data/reference_2d.json
    .venv/bin/python tests/reference_2d.py            # compares a fresh run with it

The reference in tests/data/reference_2d.json was recorded at commit 0c50637, before the
second 3-D slice (Tresca on a tangent plane, contact, the vault) and before the damage
fast path; at 0c50637 the 2.1-ex1 and 2.2-ex1 runs equalled the first reference (549c1d6, before any
3-D change) to 0.0. tests/test_3d.py::test_2d_runs_unchanged repeats the comparison.

The runs are made with the PETSc options of ``GUARD_OPTIONS``: they switch off the per-step
accelerations that change results at solver tolerance (not round-off), so that this guard isolates
the 3-D generalisation; those accelerations are checked against the plain path by their own tests.
"""
from __future__ import annotations

import argparse
import csv
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import dolfinx
import numpy as np

import os

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = ROOT / "tests" / "data" / "reference_2d.json"
#: structured meshes only (a gmsh mesh may differ between gmsh versions of the CI stacks)
#: one or more per problem; each about 2 s
CASES = {"2.1-ex1": ["--n", "10", "--k", "0.05"],                 # variant B: split, plane-stress B
         "2.2-ex1": ["--n", "8", "--k", "0.02", "--T", "0.2"],    # Phi_L(B eps), Tresca
         "2.2-ex3": ["--n", "8", "--T", "0.2"],                   # stick-slip, two friction planes
         "2.3-ex1": ["--n", "8", "--k", "0.02", "--T", "0.2"],    # memory, normal compliance
         "2.4-ex1": ["--n", "8", "--k", "0.02", "--T", "0.2"],    # viscoplastic, Tresca (P1)
         "3.1-ex2": ["--n", "8", "--T", "0.2"],                   # dynamic normal compliance
         "3.2-ex1": ["--n", "8", "--k", "0.01", "--T", "0.2"],    # dynamic bilateral Tresca
         "3.3-ex2": ["--n", "8", "--k", "0.01", "--T", "0.2",     # fully damageable, zeta = zeta*
                     "--set", "initial_damage=a"]}
#: history columns not compared: counters and timings
SKIP_COLUMNS = ("step", "step_time_s")
#: where an extreme value sits: a vertex chosen among ties by the dof order, which differs
#: between DOLFINx versions (0.11 renumbers), so compared only on the recording's version; the
#: extreme values themselves (zeta_min, penetration_max) are compared on every version
LOCATION_COLUMNS = ("zeta_min_x", "zeta_min_y", "penetration_x1", "penetration_x2")
#: PETSc options of the guard runs (see the docstring); unknown options are ignored by PETSc
GUARD_OPTIONS = "-damage_vi_fast 0"


def run_case(example_id, args, out: Path) -> dict:
    """History scalars and final fields of one run (same keys as the reference)."""
    # the recorded runs keep their k even where it exceeds k_max (3.3-ex2 at k = 0.01): the guard
    # compares with the recording, bit for bit, not with a stable run
    cmd = [sys.executable, "-m", "damage_dolfinx.cli", "run", example_id, *args, "--allow-unstable",
           "--no-figures", "--quiet", "--checkpoint-seconds", "0", "--out", str(out)]
    env = dict(os.environ, PETSC_OPTIONS=(os.environ.get("PETSC_OPTIONS", "") + " "
                                          + GUARD_OPTIONS).strip())
    subprocess.run(cmd, check=True, cwd=ROOT, capture_output=True, env=env)
    with open(out / "history.csv") as f:
        rows = list(csv.DictReader(f))
    columns = [c for c in rows[0] if c not in SKIP_COLUMNS and not c.endswith("_its")]
    fields = np.load(out / "fields_final.npz")
    names = sorted(k for k in fields.files if not k.endswith("_coords"))
    return {"args": args,
            "history": {c: [float(r[c]) for r in rows] for c in columns},
            "fields": {name: fields[name].ravel().tolist() for name in names},
            "coords": {name: fields[name + "_coords"].ravel().tolist() for name in names}}


def compare(new: dict, ref: dict, locations: bool = True) -> dict:
    """Largest relative differences: history columns (largest difference over the run relative
    to the column's largest |value|, so that a column of round-off values does not count as
    100 %) and final fields (norm-wise); coordinates must agree to 1e-12 (same mesh, same
    order); every recorded column and field must still be there. ``locations=False`` skips
    LOCATION_COLUMNS (another DOLFINx version than the recording's)."""
    out = {}
    for name in ref["fields"]:
        if name not in new["fields"]:
            raise AssertionError(f"{name}: field missing")
        if not np.allclose(new["coords"][name], ref["coords"][name], atol=1e-12):
            raise AssertionError(f"{name}: different dof coordinates (mesh or ordering changed)")
        a, b = np.asarray(new["fields"][name]), np.asarray(ref["fields"][name])
        out[f"field_{name}"] = float(np.linalg.norm(a - b) / max(np.linalg.norm(b), 1e-300))
    for c in ref["history"]:
        if not locations and c in LOCATION_COLUMNS:
            continue
        if c not in new["history"]:
            raise AssertionError(f"{c}: history column missing")
        a, b = np.asarray(new["history"][c]), np.asarray(ref["history"][c])
        if a.shape != b.shape:
            raise AssertionError(f"{c}: {a.size} steps instead of {b.size}")
        nan = np.isnan(b)
        if not np.array_equal(nan, np.isnan(a)):
            raise AssertionError(f"{c}: NaN pattern changed")
        scale = max(float(np.max(np.abs(b[~nan]), initial=0.0)), 1e-300)
        out[f"history_{c}"] = float(np.max(np.abs(a[~nan] - b[~nan]), initial=0.0) / scale)
    return out


def same_version(ref: dict) -> bool:
    """Whether this DOLFINx is the one the reference was recorded with."""
    return dolfinx.__version__ == ref["dolfinx"]


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
        REFERENCE.write_text(json.dumps({"commit": commit, "dolfinx": dolfinx.__version__,
                                         "runs": runs}) + "\n")
        print(f"recorded {', '.join(runs)} at {commit} -> {REFERENCE}")
        return
    ref = json.loads(REFERENCE.read_text())
    for ex, run in runs.items():
        diffs = compare(run, ref["runs"][ex], same_version(ref))
        print(f"{ex} vs {ref['commit']}: largest relative difference {max(diffs.values()):.2e}")
        for key, value in diffs.items():
            print(f"    {key:22s} {value:.2e}")


if __name__ == "__main__":
    main()
