"""Build the report folder RESULTS/report/ (REPORT.html with its images, REPORT.md) from what
`make figures` and `make convergence` wrote (and the committed benchmark outputs): title block
with the count of each verdict class, contents, summary (one row per thesis table and figure,
with its graded verdict and a link), known differences, the thesis's tables beside ours
(benchmarks/reproduction/fidelity.py, also written to RESULTS/fidelity/), every figure with the thesis
sentence it is checked against.

    python benchmarks/reproduction/report.py [--results results] [--pdf]

``--pdf`` also prints RESULTS/report/REPORT.pdf with headless Chromium (--print-to-pdf). The
folder is self-contained: move or zip it as a whole.
"""
import argparse
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # benchmarks/: common.py
import common  # noqa: E402,F401  (puts the checkout on sys.path)
from reproduction import build as report  # noqa: E402

p = argparse.ArgumentParser()
p.add_argument("--results", default="results")
p.add_argument("--pdf", action="store_true", help="also print REPORT.pdf with headless Chromium")
a = p.parse_args()
_made = [name for name in ("figures", "figures-quick", "convergence", "convergence-quick")
         if (Path(a.results) / name / "index.json").is_file()]
if not _made:  # a report of no results would judge nothing: refused, nothing written
    p.error(f"{a.results!r} holds no results of make figures, figures-quick or convergence "
            "(their index.json): run one of them first, or give --results the folder they wrote")
page = report.build(a.results)
counts = re.search(r"\*\*(of \d+ thesis .*?)\*\*", page.with_suffix(".md").read_text())
print(f"report: {page.parent}/ (REPORT.html, REPORT.md, images/)"
      + (f": {counts.group(1)}" if counts else ""))
chromium = shutil.which("chromium") or shutil.which("chromium-browser")
if a.pdf and chromium:
    with tempfile.TemporaryDirectory() as profile:
        subprocess.run([chromium, "--headless", "--no-sandbox", "--disable-gpu",
                        "--disable-background-networking", "--disable-component-update",
                        "--disable-sync", "--no-first-run", f"--user-data-dir={profile}",
                        "--virtual-time-budget=15000", "--no-pdf-header-footer",
                        f"--print-to-pdf={page.with_suffix('.pdf')}", page.as_uri()],
                       check=True, capture_output=True, timeout=300)
    print(f"pdf: {page.with_suffix('.pdf')}")
elif a.pdf:
    print("pdf: chromium not found (make setup installs it)")
