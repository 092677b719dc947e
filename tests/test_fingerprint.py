"""The run fingerprint is canonical: the same problem gives the same fingerprint whatever the
number of ranks, the Python hash seed or how many UFL objects (constants, functions, labels,
indices) the process made before; a changed law is named as the law, a changed constant of a
load as the load. A restart on 1 -> 2 -> 3 ranks under different hash seeds is accepted."""
import json
import subprocess
import sys
import textwrap

import pytest

from conftest import ENV

SCRIPT = textwrap.dedent('''
    import json, sys
    import numpy as np
    import ufl
    from mpi4py import MPI
    from dolfinx import fem
    import damage_dolfinx as dd
    from damage_dolfinx.geometries.rectangle import rectangle, side

    what, out, T, extra, variant = sys.argv[1], sys.argv[2], float(sys.argv[3]), \\
        int(sys.argv[4]), sys.argv[5]

    def mesh(comm, n):
        return rectangle(comm, (0.0, 0.0), (2.0, 0.5), 4 * n, n,
                         {1: side(0, 0.0), 2: side(0, 2.0), 3: side(1, 0.0)})

    # objects made before the problem shift every UFL count of this process
    junk_mesh = mesh(MPI.COMM_WORLD, 1).mesh
    junk = [fem.Constant(junk_mesh, 1.0) for _ in range(extra)] + \\
        [ufl.variable(ufl.SpatialCoordinate(junk_mesh)[0]) for _ in range(extra)] + \\
        [ufl.indices(3) for _ in range(extra)]
    scale = {}

    def traction(x, t):
        if "c" not in scale:  # a constant of the load: its value is part of the fingerprint
            scale["c"] = fem.Constant(x.ufl_domain(),
                                      40.0 * (100.0 if variant == "load" else 1.0))
        return ufl.as_vector((scale["c"] * t * (1.0 + 0.1 * x[1]), 0.0))

    def law(eps, zeta, p):
        i, j = ufl.indices(2)
        z = ufl.variable(zeta)
        factor = 2.0 if variant == "law" else 1.0
        return -100.0 * factor * eps[i, j] * eps[i, j] + 0.0 * ufl.diff(z ** 2, z)

    problem = dd.Problem(model="2.2", mesh=mesh, n=3, T=T, k=0.01,
                         boundaries={"clamped": 1, "traction": 2, "tresca": 3},
                         traction=traction, damage_law=dd.DamageLaw(law, "own"),
                         params={"E": 2000.0, "g_fric": 10.0})
    if what == "fingerprint":
        from damage_dolfinx.runtime import checkpoint
        ex = problem.checked()
        fp = checkpoint.fingerprint(ex, ex.problem_data(MPI.COMM_WORLD, n=3))
        if MPI.COMM_WORLD.rank == 0:
            print(json.dumps(fp, sort_keys=True))
    else:
        try:
            dd.run(problem, out, restart=what == "restart", checkpoint_every=1, figures=False,
                   progress=False)
        except dd.InputError as exc:  # raised as an InputError on every rank
            if MPI.COMM_WORLD.rank == 0:
                print(f"damage-dolfinx: error: {exc}", file=sys.stderr)
            sys.exit(2)
''')


def _python(tmp_path, ranks, seed, *args):
    script = tmp_path / "fp.py"
    script.write_text(SCRIPT)
    cmd = [sys.executable, str(script), *map(str, args)]
    if ranks > 1:
        cmd = ["mpirun", "-n", str(ranks), *cmd]
    env = dict(ENV, PYTHONHASHSEED=str(seed))
    return subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=300)


def _fingerprint(tmp_path, ranks, seed, extra, variant="same"):
    proc = _python(tmp_path, ranks, seed, "fingerprint", "-", 0.03, extra, variant)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1])


def test_fingerprint_is_the_same_whatever_the_ranks_seed_and_ufl_counts(tmp_path):
    base = _fingerprint(tmp_path, 1, 0, 0)
    assert _fingerprint(tmp_path, 1, 12345, 7) == base
    assert _fingerprint(tmp_path, 2, 1, 3) == base
    assert _fingerprint(tmp_path, 3, 99, 0) == base
    law = _fingerprint(tmp_path, 1, 5, 2, "law")
    assert [key for key in base if base[key] != law[key]] == ["damage_law"]
    load = _fingerprint(tmp_path, 2, 7, 0, "load")
    assert [key for key in base if base[key] != load[key]] == ["traction"]


@pytest.mark.mpi
def test_restart_on_1_2_3_ranks_with_other_hash_seeds_is_accepted(tmp_path):
    out = tmp_path / "run"
    steps = [(1, 0, 0.02, 0), (2, 17, 0.04, 5), (3, 4242, 0.06, 2)]
    for i, (ranks, seed, T, extra) in enumerate(steps):
        proc = _python(tmp_path, ranks, seed, "restart" if i else "run", out, T, extra, "same")
        assert proc.returncode == 0, proc.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "completed" and summary["steps_done"] == 6
    assert [r["mpi_size"] for r in summary["restarts"]] == [2, 3]
    for variant, item in (("law", "the damage law differs"), ("load", "the traction differs")):
        proc = _python(tmp_path, 2, 3, "restart", out, 0.08, 1, variant)
        assert proc.returncode == 2, proc.stderr
        lines = [line for line in proc.stderr.splitlines() if line.startswith("damage-dolfinx:")]
        assert len(lines) == 1 and item in lines[0] and "Traceback" not in proc.stderr, \
            proc.stderr
    assert json.loads((out / "summary.json").read_text())["steps_done"] == 6
