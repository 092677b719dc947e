"""A reduced convergence study of each of the seven problems, run by two checkouts of the package
(their interpreters), and the two error tables compared: the scheme's results unchanged by a
change of code, beyond the solver tolerance.

    python benchmarks/studies/convergence_ab.py OLD_PYTHON NEW_PYTHON [--only 3.1-ex1 ...]
        [--out benchmarks/reference_output/convergence_ab]

Each study: `converge ID --ref-n R --ref-k 0.005 --n R/4 R/2 --k 0.02 0.01` (R = 64; 80 for
2.1-ex1, whose hole needs a multiple of 5), the whole time interval, the example's default
reading, serial. Per problem: the largest relative difference between the two errors.csv over
every cell and error column, not the wall times (|a - b| / max(|a|, |b|), exact zeros equal), both studies' wall
times, and "same" when that difference is below 1e-6 (the iterative solves stop at relative
tolerances of 1e-8 to 1e-10; an error of the discrete solution is a difference of two runs, so
1e-6 relative leaves two orders of room). Writes convergence_ab.json and convergence_ab.md."""
import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from common import RECORDS  # noqa: E402

#: the problems (2.2's convergence study is its Example 2) and their reference mesh
PROBLEMS = [("2.1-ex1", 80), ("2.2-ex2", 64), ("2.3-ex1", 64), ("2.4-ex1", 64),
            ("3.1-ex1", 64), ("3.2-ex1", 64), ("3.3-ex1", 64)]
REF_K, KS = 0.005, (0.02, 0.01)
SAME = 1e-6


def checkout_commit(python) -> str:
    """Short hash of the checkout an interpreter imports the package from ('unknown' without
    git)."""
    where = subprocess.run([python, "-c", "import damage_dolfinx, os; "
                            "print(os.path.dirname(os.path.dirname(damage_dolfinx.__file__)))"],
                           capture_output=True, text=True, cwd="/").stdout.strip()
    try:
        r = subprocess.run(["git", "-C", where, "rev-parse", "--short", "HEAD"],
                           capture_output=True, text=True)
    except OSError:
        return "unknown"
    return r.stdout.strip() or "unknown"


def study(python, example_id, ref_n, folder) -> tuple:
    """(rows of errors.csv as dicts, wall seconds) of one reduced study."""
    args = [python, "-m", "damage_dolfinx.cli", "converge", example_id, "--ref-n", str(ref_n),
            "--ref-k", repr(REF_K), "--n", str(ref_n // 4), str(ref_n // 2),
            "--k", *map(repr, KS), "--quiet", "--out", str(folder)]
    start = time.perf_counter()
    r = subprocess.run(args, capture_output=True, text=True, cwd=folder.parent)  # not this checkout
    wall = time.perf_counter() - start
    if r.returncode:
        raise SystemExit(f"{python}: {' '.join(args[2:])} exited {r.returncode}: "
                         f"{r.stderr.strip().splitlines()[-1:]}")
    with open(folder / "errors.csv") as f:
        return list(csv.DictReader(f)), wall


def difference(old, new) -> tuple:
    """(largest relative difference over the numeric cells, number of values compared)."""
    if len(old) != len(new) or (old and set(old[0]) != set(new[0])):
        raise SystemExit("the two error tables have different rows or columns")
    worst, count = 0.0, 0
    for a, b in zip(old, new):
        for key in a:
            if key == "wall_time_s":
                continue
            try:
                x, y = float(a[key]), float(b[key])
            except ValueError:
                if a[key] != b[key]:
                    raise SystemExit(f"column {key}: {a[key]!r} against {b[key]!r}")
                continue
            scale = max(abs(x), abs(y))
            worst = max(worst, abs(x - y) / scale if scale else 0.0)
            count += 1
    return worst, count


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("old_python")
    ap.add_argument("new_python")
    ap.add_argument("--only", nargs="+", help="example ids (default: all seven)")
    ap.add_argument("--out", default=str(RECORDS / "convergence_ab"))
    args = ap.parse_args()
    args.old_python, args.new_python = map(os.path.abspath, (args.old_python, args.new_python))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for example_id, ref_n in PROBLEMS:
        if args.only and example_id not in args.only:
            continue
        with tempfile.TemporaryDirectory() as tmp:
            old, t_old = study(args.old_python, example_id, ref_n, Path(tmp) / "old")
            new, t_new = study(args.new_python, example_id, ref_n, Path(tmp) / "new")
        worst, count = difference(old, new)
        rows.append({"example": example_id, "ref_n": ref_n, "n": [ref_n // 4, ref_n // 2],
                     "ref_k": REF_K, "k": list(KS), "values": count, "max_rel_diff": worst,
                     "same": worst < SAME, "old_s": round(t_old, 2), "new_s": round(t_new, 2)})
        print(f"{example_id}: {count} values, largest relative difference {worst:.2e}, "
              f"{t_old:.1f} s -> {t_new:.1f} s", flush=True)
    old_commit, new_commit = checkout_commit(args.old_python), checkout_commit(args.new_python)
    (out / "convergence_ab.json").write_text(json.dumps(
        {"old": old_commit, "new": new_commit, "threshold": SAME, "rows": rows}, indent=1) + "\n")
    lines = ["# Reduced convergence studies: two versions of the code compared", "",
             "Written by `python benchmarks/studies/convergence_ab.py OLD_PYTHON NEW_PYTHON` "
             f"(old: commit {old_commit}, new: commit {new_commit}). Each study: reference n = R, k = {REF_K}; coarse "
             f"n = R/4, R/2 and k = {KS[0]}, {KS[1]}; T and data of the example; serial. "
             f"'same': every error of errors.csv within {SAME:g} relative.", "",
             "| problem | R | values | largest relative difference | same | old [s] | new [s] |",
             "|---|---|---|---|---|---|---|"]
    lines += [f"| {r['example']} | {r['ref_n']} | {r['values']} | {r['max_rel_diff']:.1e} | "
              f"{'yes' if r['same'] else 'NO'} | {r['old_s']} | {r['new_s']} |" for r in rows]
    (out / "convergence_ab.md").write_text("\n".join(lines) + "\n")
    if not all(r["same"] for r in rows):
        raise SystemExit(1)


if __name__ == "__main__":
    main()
