"""Where the time of one whole run goes: imports and command line, set-up, stepping,
bookkeeping, field output, figures (a profiled process, cProfile):

    python benchmarks/performance/run_profile.py 3.1-ex1 --n 128 --k 0.005 [-- more run options]

Runs ``damage-dolfinx run ID --n N --k K --quiet --overwrite`` (default outputs) under cProfile
in this process and prints the cumulative seconds of: the imports and everything before the
run starts (whole minus the run), the set-up (mesh, forms, solvers, stability check), the
steps (the models' advance), the bookkeeping (history rows and scalars, the per-step state
check), the field output (XDMF series, final fields) and the figures. Profiling adds its own
overhead to Python-heavy parts (figures, bookkeeping) more than to the solves."""
import argparse
import cProfile
import pstats
import sys
import tempfile
import time

PARTS = {  # (file suffix, function name) whose cumulative time is the part
    "set-up (mesh, forms, solvers, stability)": [("runtime/loop.py", "_set_up")],
    "stepping (advance)": [("models/base.py", "advance")],
    "bookkeeping (history scalars and rows, state check)": [("runtime/records.py", "record"),
                                                            ("runtime/records.py", "end_of_step")],
    "field output (XDMF, final npz)": [("runtime/records.py", "write_fields"),
                                       ("runtime/io.py", "save_final_fields")],
    "figures": [("runtime/records.py", "figure")],
    "of which the stability check": [("numerics/stability.py", "estimate_stability")],
}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("example")
    ap.add_argument("--n", required=True)
    ap.add_argument("--k", required=True)
    args, rest = ap.parse_known_args()
    out = tempfile.mkdtemp()
    argv = ["run", args.example, "--n", args.n, "--k", args.k, "--quiet", "--overwrite",
            "--out", out, *[a for a in rest if a != "--"]]
    profile = cProfile.Profile()
    start = time.perf_counter()
    profile.enable()
    from damage_dolfinx.cli import main as cli_main
    status = cli_main(argv)
    profile.disable()
    whole = time.perf_counter() - start
    stats = pstats.Stats(profile).stats
    cum = {}
    for (path, _, name), (_, _, _, ct, _) in stats.items():
        cum[(path.replace("\\", "/"), name)] = cum.get((path, name), 0.0) + ct
    print(f"{args.example} n = {args.n}, k = {args.k} (status {status}), profiled:")
    print(f"  whole process (after the interpreter start): {whole:.2f} s")
    run = sum(t for (p, f), t in cum.items() if p.endswith("runtime/runner.py") and f == "run")
    print(f"  imports and command line before the run: {whole - run:.2f} s")
    for label, keys in PARTS.items():
        t = sum(v for (p, f), v in cum.items() for s, n in keys if p.endswith(s) and f == n)
        print(f"  {label}: {t:.2f} s")
    return status


if __name__ == "__main__":
    sys.exit(main())
