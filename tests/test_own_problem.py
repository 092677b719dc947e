"""The public API on problems of one's own: a user rectangle, mesh files written by gmsh, user
damage laws, irreversibility, the refusal of unstable time steps, and the catalogue built on
public names only."""
import ast
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import ufl
from mpi4py import MPI

import damage_dolfinx as dd
from conftest import ENV
from damage_dolfinx.geometries.rectangle import rectangle, side

REPO = Path(__file__).resolve().parents[1]
CLI = [sys.executable, "-m", "damage_dolfinx.cli"]


def cli(*args, cwd=None):
    return subprocess.run(CLI + [str(a) for a in args], capture_output=True, text=True, cwd=cwd,
                          env=ENV, timeout=600)


def mpirun(*args, cwd=None):
    return subprocess.run(["mpirun", "-n", "2", sys.executable] + [str(a) for a in args],
                          capture_output=True, text=True, cwd=cwd, env=ENV, timeout=600)


def rect_mesh(comm, n):  # (0, 2) x (0, 0.5): 1 left, 2 right, 3 bottom
    return rectangle(comm, (0.0, 0.0), (2.0, 0.5), 4 * n, n,
                     {1: side(0, 0.0), 2: side(0, 2.0), 3: side(1, 0.0)})


def threshold(eps, zeta, p):
    return -p.extra["lam"] * ufl.max_value(ufl.inner(eps, eps) - p.extra["eps0"] ** 2, 0.0)


def rect_problem(**changes):
    data = dict(model="2.2", mesh=rect_mesh, n=4, T=0.1,
                boundaries={"clamped": 1, "traction": 2, "tresca": 3},
                traction=lambda x, t: ufl.as_vector((40.0 * t, 0.0)),
                params={"E": 2000.0, "nu": 0.25, "g_fric": 10.0})
    data.update(changes)
    return dd.Problem(**data)


def write_msh(path, dim=2, tagged=True):
    """A rectangle (2-D) or box (3-D) written by gmsh, physical curves 1-3 and surface 1."""
    import gmsh
    from damage_dolfinx.geometries import gmsh_session
    gmsh = gmsh_session()
    gmsh.model.add("test_msh")
    if dim == 2:
        s = gmsh.model.occ.addRectangle(0, 0, 0, 1, 1)
        gmsh.model.occ.synchronize()
        if tagged:
            curves = {}
            for _, c in gmsh.model.getEntities(1):
                x = gmsh.model.occ.getCenterOfMass(1, c)
                if abs(x[0]) < 1e-9:
                    curves.setdefault(1, []).append(c)
                elif abs(x[0] - 1) < 1e-9:
                    curves.setdefault(2, []).append(c)
                elif abs(x[1]) < 1e-9:
                    curves.setdefault(3, []).append(c)
            for tag, cs in curves.items():
                gmsh.model.addPhysicalGroup(1, cs, tag)
        gmsh.model.addPhysicalGroup(2, [s], 1)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.25)
        gmsh.model.mesh.generate(2)
    else:
        v = gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
        gmsh.model.occ.synchronize()
        gmsh.model.addPhysicalGroup(3, [v], 1)
        gmsh.model.addPhysicalGroup(2, [s for _, s in gmsh.model.getEntities(2)], 1)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
        gmsh.model.mesh.generate(3)
    gmsh.write(str(path))
    gmsh.model.remove()
    return path


def test_rectangle_run_writes_a_run_folder(tmp_path):
    problem = rect_problem(damage_law=dd.DamageLaw(threshold, "threshold"),
                           params={"E": 2000.0, "g_fric": 10.0, "lam": 5e3, "eps0": 2e-3})
    summary = dd.run(problem, tmp_path / "run", progress=False)
    assert summary["status"] == "completed"
    for name in ("summary.json", "fields.xdmf", "history.csv", "fields_final.png"):
        assert (tmp_path / "run" / name).is_file(), name
    on_disk = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert on_disk["final"]["zeta_min"] >= 0.01 - 1e-9 and on_disk["final"]["u_L2"] > 0
    assert any("threshold" in a for a in on_disk["assumptions"])


def test_user_law_equal_to_the_thesis_law_gives_the_thesis_result_bit_for_bit(tmp_path):
    from damage_dolfinx.numerics.damage import phi_A
    base = dd.run(rect_problem(), tmp_path / "thesis", progress=False, figures=False)
    own = dd.run(rect_problem(damage_law=dd.DamageLaw(phi_A, "phi_A written out")),
                 tmp_path / "user", progress=False, figures=False)
    a = np.load(tmp_path / "thesis" / "fields_final.npz")
    b = np.load(tmp_path / "user" / "fields_final.npz")
    for key in a.files:
        assert np.array_equal(a[key], b[key]), key
    assert base["final"] == own["final"]


def test_irreversible_damage_never_increases():
    """A healing-dominated law: without irreversibility zeta grows back towards 1, with it every
    nodal value stays at or below its previous value at every step."""
    heal = dd.DamageLaw(lambda e, z, p: 5.0 * (1.0 - z) - 50.0 * ufl.inner(e, e) * 1e4, "heal")
    for irreversible in (False, True):
        problem = rect_problem(damage_law=heal, irreversible=irreversible, zeta0=0.5)
        stepper = problem.checked().build(MPI.COMM_WORLD)
        stepper.initialize()
        rises = 0.0
        for _ in range(stepper.num_steps):
            before = stepper.zeta.x.array.copy()
            stepper.advance()
            rises = max(rises, float(np.max(stepper.zeta.x.array - before)))
        if irreversible:
            assert rises <= 1e-12
        else:
            assert rises > 1e-3  # the law does heal: the bound is what stops it


@pytest.mark.mpi
def test_threshold_law_serial_equals_two_ranks(tmp_path):
    script = tmp_path / "own.py"
    script.write_text(f"""
import sys, ufl
sys.path.insert(0, {str(REPO / 'tests')!r})
from test_own_problem import rect_problem, threshold
import damage_dolfinx as dd
problem = rect_problem(damage_law=dd.DamageLaw(threshold, "threshold"), irreversible=True,
                       params={{"E": 2000.0, "g_fric": 10.0, "lam": 5e3, "eps0": 2e-3}})
dd.run(problem, sys.argv[1], progress=False, figures=False)
""")
    serial = subprocess.run([sys.executable, script, tmp_path / "s"], capture_output=True,
                            text=True, env=ENV, timeout=600)
    assert serial.returncode == 0, serial.stderr
    parallel = mpirun(script, tmp_path / "p")
    assert parallel.returncode == 0, parallel.stderr
    a, b = np.load(tmp_path / "s" / "fields_final.npz"), np.load(tmp_path / "p" / "fields_final.npz")
    for key in ("u", "zeta", "v"):
        assert np.max(np.abs(a[key] - b[key])) <= 1e-8 * max(1.0, np.max(np.abs(a[key]))), key


def test_gmsh_file_through_the_cli(tmp_path):
    msh = write_msh(tmp_path / "rect.msh")
    r = cli("run", "2.2-ex1", "--mesh", msh, "--T", "0.04", "--k", "0.01", "--quiet",
            "--no-figures", "--out", tmp_path / "run")
    assert r.returncode == 0, r.stderr
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["status"] == "completed" and summary["final"]["u_L2"] > 0


@pytest.mark.parametrize("case, expected", [
    ("untagged", "lacks the boundary tags"),
    ("empty", "is empty"),
    ("text", "is not a gmsh .msh file"),
    ("garbage", "gmsh cannot read it"),
    ("3d", "3-D mesh"),
])
def test_bad_mesh_files_are_refused_with_one_line(tmp_path, case, expected):
    def text(name, content):
        (tmp_path / name).write_text(content)
        return tmp_path / name

    path = {"untagged": lambda: write_msh(tmp_path / "u.msh", tagged=False),
            "empty": lambda: text("e.msh", ""),
            "text": lambda: text("t.txt", "hello\n"),
            "garbage": lambda: text("g.msh", "$MeshFormat\nnonsense\n"),
            "3d": lambda: write_msh(tmp_path / "box.msh", dim=3)}[case]()
    r = cli("run", "2.2-ex1", "--mesh", path, "--T", "0.02", "--k", "0.01", "--quiet",
            "--out", tmp_path / "run")
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and expected in lines[0], r.stderr


def test_missing_tag_is_refused_naming_it(tmp_path):
    problem = rect_problem(boundaries={"clamped": 1, "traction": 7, "tresca": 3})
    with pytest.raises(dd.InputError, match="traction tag 7 is missing or empty"):
        dd.run(problem, tmp_path / "run", progress=False)
    assert not (tmp_path / "run" / "summary.json").exists()


def test_a_chosen_k_above_k_max_is_refused(tmp_path):
    r = cli("run", "2.2-ex1", "--n", "4", "--k", "0.03", "--T", "0.06", "--quiet",
            "--out", tmp_path / "run")
    assert r.returncode == 2 and "k_max = 0.02" in r.stderr, r.stderr
    r = cli("run", "2.2-ex1", "--n", "4", "--k", "0.03", "--T", "0.06", "--quiet",
            "--no-figures", "--allow-unstable", "--out", tmp_path / "run")
    assert r.returncode == 0, r.stderr
    with pytest.raises(dd.InputError, match="k_max"):
        dd.run(rect_problem(k=0.05), tmp_path / "api", progress=False)


def test_default_k_divides_any_final_time():
    from damage_dolfinx.catalogue.examples import get
    ex = get("3.3-ex3")
    grid = ex.configure(h=0.3, T=0.5).time
    assert grid.num_steps * grid.k == pytest.approx(0.5, rel=1e-12) and grid.k <= ex.k
    grid = ex.configure(h=0.075, T=0.5).time
    assert grid.k <= ex.k * 0.5 * (1 + 1e-9)
    grid = ex.configure().time
    assert grid.k == ex.k  # the example's own k, bit for bit


def test_catalogue_imports_only_public_names():
    """The thesis catalogue is a client of the public API: its modules import the package's
    public names (from the module that defines each one: the catalogue stands below the face
    in the layers), the geometries and forms packages, and the catalogue itself."""
    allowed_modules = ("damage_dolfinx.geometries", "damage_dolfinx.forms", "damage_dolfinx.models.blocks",
                       "damage_dolfinx.catalogue")
    from damage_dolfinx import _WHERE
    public = {(f"damage_dolfinx.{where}", name) for name, where in _WHERE.items()}
    public |= {("damage_dolfinx.models.registry", "default_parameters"),   # model_defaults
               ("damage_dolfinx.models.registry", "register"),             # register_model
               ("damage_dolfinx.models.registry", "model")}                # model_class
    bad = []
    for path in sorted((REPO / "damage_dolfinx" / "catalogue").glob("*.py")):
        if path.name in ("__init__.py", "examples.py"):  # the catalogue's own machinery
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.module and \
                    node.module.startswith("damage_dolfinx"):
                if node.module == "damage_dolfinx":
                    bad += [f"{path.name}: {a.name}" for a in node.names
                            if a.name not in dd.__all__]
                elif not node.module.startswith(allowed_modules):
                    bad += [f"{path.name}: {node.module}.{a.name}" for a in node.names
                            if (node.module, a.name) not in public]
            elif isinstance(node, ast.Import):
                bad += [f"{path.name}: {a.name}" for a in node.names
                        if a.name.startswith("damage_dolfinx")]
    assert not bad, bad
