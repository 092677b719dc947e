"""A straightforward DOLFINx script against the package on the same problem: both run as whole
processes in turn (script, package, script, ...), the package with its default outputs
(figures, XDMF series, history), then the final fields are compared.

    python benchmarks/performance/plain/plain_vs_package.py 3.1-ex1 [--pairs 3] [--out DIR]

Problems with a script here (the sizes of the comparison): 2.1-ex1 (n = 160, k = 0.01), 3.1-ex1
(n = 128, k = 0.005), 2.2-ex1, 2.3-ex1, 2.4-ex1, 3.2-ex1, 3.3-ex1 (n = 64, k = 0.002). Prints
the wall time of each process, the median ratio script / package (the package's speed-up) and
the relative difference of the final u and zeta."""
import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from compare import main as compare  # noqa: E402

CASES = {"2.1-ex1": ("elastic_2_1.py", 160, 0.01), "2.2-ex1": ("kelvin_voigt_2_2.py", 64, 0.002),
         "2.3-ex1": ("memory_2_3.py", 64, 0.002), "2.4-ex1": ("viscoplastic_2_4.py", 64, 0.002),
         "3.1-ex1": ("dynamic_3_1.py", 128, 0.005),
         "3.2-ex1": ("dynamic_tresca_3_2.py", 64, 0.002),
         "3.3-ex1": ("fully_damageable_3_3.py", 64, 0.002)}


def wall(cmd):
    start = time.perf_counter()
    subprocess.run(cmd, check=True, capture_output=True)
    return time.perf_counter() - start


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("example", choices=sorted(CASES))
    ap.add_argument("--pairs", type=int, default=3)
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    script, n, k = CASES[args.example]
    out = Path(args.out or tempfile.mkdtemp())
    plain = [sys.executable, str(HERE / script), "--n", str(n), "--k", str(k),
             "--out", str(out / "script")]
    package = [sys.executable, "-m", "damage_dolfinx.cli", "run", args.example, "--n", str(n),
               "--k", str(k), "--quiet", "--overwrite", "--out", str(out / "package")]
    wall(plain), wall(package)  # warm-up: compiled forms in the cache
    ratios = []
    for _ in range(args.pairs):
        a, b = wall(plain), wall(package)
        ratios.append(a / b)
        print(f"script {a:.2f} s, package {b:.2f} s, ratio {a / b:.2f}", flush=True)
    print(f"{args.example}: speed-up (script / package, median of {args.pairs}) "
          f"{statistics.median(ratios):.2f}")
    compare(out / "script", out / "package")


if __name__ == "__main__":
    main()
