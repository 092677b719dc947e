"""Build results/REPORT.md and results/REPORT.html from what `make figures` and
`make convergence` wrote (and the committed benchmark outputs).

    python benchmarks/report.py [--results results]
"""
import argparse

from damage_dolfinx import report

p = argparse.ArgumentParser()
p.add_argument("--results", default="results")
a = p.parse_args()
page = report.build(a.results)
print(f"report: {page} and {page.with_suffix('.md')}")
