"""The run fingerprint is canonical: the same problem gives the same fingerprint whatever the
number of ranks, the Python hash seed or how many UFL objects (constants, functions, labels,
indices) the process made before; a changed law is named as the law, a changed constant of a
load as the load, a zeta0(x) changed inside (same range) as zeta0, by a digest of its values at
the nodes gathered in an order no partition changes. A restart on 1 -> 2 -> 3 ranks under
different hash seeds is accepted."""
import json
import subprocess
import sys
import textwrap

import pytest

from conftest import ENV, tool_lines

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
                         params={"E": 2000.0, "g_fric": 10.0},
                         # two values only: "zeta0" changes it inside, not its min or max
                         zeta0=lambda x: 0.5 + 0.5 * (x[0] > (1.5 if variant == "zeta0" else
                                                              1.0)))
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
    zeta0 = _fingerprint(tmp_path, 3, 8, 0, "zeta0")  # a digest of its nodal values
    assert [key for key in base if base[key] != zeta0[key]] == ["zeta0"]


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
    for variant, item in (("law", "the damage law changed"), ("load", "the traction changed"),
                          ("zeta0", "the initial damage zeta0 changed")):
        proc = _python(tmp_path, 2, 3, "restart", out, 0.08, 1, variant)
        assert proc.returncode == 2, proc.stderr
        lines = tool_lines(proc.stderr)
        assert len(lines) == 1 and item in lines[0] and "Traceback" not in proc.stderr, \
            proc.stderr
    assert json.loads((out / "summary.json").read_text())["steps_done"] == 6


def _study_problem(law_factor=1.0, wide=2.0):
    import ufl
    import damage_dolfinx as dd
    from damage_dolfinx.geometries.rectangle import rectangle, side

    def mesh(comm, n):  # ``wide`` changes the finest level only
        length = wide if n >= 8 else 2.0
        return rectangle(comm, (0.0, 0.0), (length, 0.5), 4 * n, n,
                         {1: side(0, 0.0), 2: side(0, length), 3: side(1, 0.0)})

    return dd.Problem(model="2.2", mesh=mesh, n=2, T=0.04, k=0.01,
                      boundaries={"clamped": 1, "traction": 2, "tresca": 3},
                      traction=lambda x, t: ufl.as_vector((40.0 * t, 0.0)),
                      damage_law=dd.DamageLaw(
                          lambda e, z, p: -100.0 * law_factor * ufl.inner(e, e), "own"),
                      params={"E": 2000.0, "g_fric": 10.0})


def test_every_level_of_a_study_restart_checks_the_run_fingerprint(tmp_path, capsys):
    """converge(restart=True): the same study has nothing to do; a changed law, or a mesh
    family changed at its finest level only, is refused naming the item and the level, and
    the study's files are unchanged."""
    import damage_dolfinx as dd
    out = tmp_path / "study"
    levels = dict(n=[2, 4], k=[0.02], ref_n=8, ref_k=0.01, T=0.04, progress=False)
    first = dd.converge(_study_problem(), out, **levels)
    assert first["status"] == "completed" and set(first["fingerprints"]) == {"2", "4", "8"}
    files = {f.name: f.read_bytes() for f in out.iterdir() if f.is_file()}
    again = dd.converge(_study_problem(), out, restart=True, **levels)
    assert again["errors"] == first["errors"] and "nothing to do" in capsys.readouterr().out
    for problem, line in ((_study_problem(law_factor=2.0), "the damage law changed"),
                          (_study_problem(wide=2.5), "the mesh changed")):
        with pytest.raises(dd.InputError) as info:
            dd.converge(problem, out, restart=True, **levels)
        text = str(info.value)
        assert text.startswith(f"cannot restart: {line} since the study in ") and \
            "at the reference mesh n = 8" in text and "\n" not in text, text
    assert {f.name: f.read_bytes() for f in out.iterdir() if f.is_file()} == files
