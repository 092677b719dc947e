"""The refused-k table: per problem, the stability limit k_max of its explicit terms at a small
and at the reference mesh, and what a run at 1.5 k_max says (exit status and message).

    python benchmarks/studies/k_max_table.py [--out benchmarks/reference_output/stability]

Writes k_max_table.json and k_max_table.md. k_max: the closed forms of 2.2 (2/m_visc) and 2.4
(2/(1 - zeta*)), the eigenvalue estimate of the steppers of 3.1-3.3 (undamaged body, Gamma_C
fully in contact)."""
import argparse
import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path

from mpi4py import MPI

REPO = Path(__file__).resolve().parents[2]
#: (example, small mesh, reference mesh): structured n or gmsh h
CASES = [("2.2-ex1", {"n": 4}, {"n": 16}), ("2.4-ex1", {"n": 4}, {"n": 16}),
         ("3.1-ex1", {"n": 4}, {"n": 32}), ("3.2-ex1", {"n": 4}, {"n": 16}),
         ("3.3-ex1", {"n": 4}, {"n": 16}), ("3.3-ex3", {"h": 0.6}, {"h": 0.15})]


def k_max(example_id, mesh):
    from damage_dolfinx.catalogue.examples import get
    from damage_dolfinx.models.registry import quasistatic_k_max
    ex = get(example_id)
    closed = quasistatic_k_max(ex.model, ex.params)
    if math.isfinite(closed):
        return closed
    from damage_dolfinx.numerics.stability_bound import exact_estimates
    with exact_estimates():
        stepper = ex.build(MPI.COMM_SELF, **mesh, overrides={"stability_check": "warn"})
    if isinstance(getattr(stepper, "stability", None), dict) and stepper.stability:
        return float(stepper.stability["k_max"])
    return float(stepper.k_max)


def refused(example_id, mesh, k):
    with tempfile.TemporaryDirectory() as tmp:
        args = [sys.executable, "-m", "damage_dolfinx.cli", "run", example_id, "--k", repr(k),
                "--T", repr(2 * k), "--quiet", "--no-figures", "--out", str(Path(tmp) / "run")]
        for key, value in mesh.items():
            args += [f"--{key}", str(value)]
        r = subprocess.run(args, capture_output=True, text=True)
    return r.returncode, (r.stderr.strip().splitlines() or [""])[-1]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(REPO / "benchmarks" / "reference_output" / "stability"))
    out = Path(ap.parse_args().out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for example_id, small, reference in CASES:
        for label, mesh in (("small", small), ("reference", reference)):
            km = k_max(example_id, mesh)
            status, message = refused(example_id, mesh, 1.5 * km)
            rows.append({"example": example_id, "mesh": label, **mesh, "k_max": km,
                         "k_run": 1.5 * km, "exit": status, "message": message})
            print(f"{example_id} {mesh} k_max = {km:.4g}: exit {status}: {message}", flush=True)
    (out / "k_max_table.json").write_text(json.dumps(rows, indent=1) + "\n")
    lines = ["| example | mesh | k_max | run at 1.5 k_max: exit | message |", "|---|---|---|---|---|"]
    for r in rows:
        mesh = ", ".join(f"{k} = {r[k]}" for k in ("n", "h") if k in r)
        lines.append(f"| {r['example']} | {mesh} | {r['k_max']:.4g} | {r['exit']} | "
                     f"{r['message'].replace('|', '/')} |")
    (out / "k_max_table.md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
