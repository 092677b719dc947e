"""Bad input, tried as a careless user would: every case runs the real command line and records
its exit status, its message (the first line of stderr), the files of its folder before and
after, and the outcome. Writes bad_inputs.json and bad_inputs.md beside this script.

    python benchmarks/faults/bad_inputs.py [--only ID ...] [--start I] [--stop J] [--out DIR]

Outcomes: ``refused`` (exit status 2, one line, nothing written or changed), ``failed`` (exit
status 3, one line, summary.json "failed" with the error), ``warned`` (exit status 0 and one
warning line), ``ok`` (exit status 0: a case that must work, e.g. --overwrite beside a user's
files), and the ones that must never happen: ``traceback``, ``user file touched``, ``invalid
JSON`` (a JSON file a strict parser rejects), ``other``. A case passes when its outcome is the
one expected. The fast cases also run in tests/test_bad_inputs.py.
"""
import argparse
import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1", MPLBACKEND="Agg", OMP_NUM_THREADS="1")
#: a tiny run (4 steps) and a tiny study, copied into the cases that need an earlier one
RUN = ["run", "2.1-ex1", "--n", "5", "--k", "0.25", "--no-figures", "--quiet"]
STUDY = ["converge", "2.1-ex1", "--ref-n", "10", "--ref-k", "0.125", "--n", "5",
         "--k", "0.25", "0.5", "--quiet"]
SWEEP = ["sweep", "2.1-ex1", "--n", "5", "--k", "0.25", "--no-figures", "--quiet", "--set",
         "kappa=1,2"]
#: a folder name (in the case's own working folder)
OUT = "o"


# ---------------------------------------------------------------------------- fixtures
def _strict(text):
    def refuse(name):
        raise ValueError(f"bare {name} is not JSON")
    return json.loads(text, parse_constant=refuse)


def user_files(work, where, names):
    """Files the user made in ``work``/``where``; returns their paths relative to the case's
    folder ``work`` (recorded as such: they must stay byte for byte)."""
    folder = work / where
    folder.mkdir(parents=True, exist_ok=True)
    for name in names:
        (folder / name).write_bytes(f"the user's own {name}\n".encode())
    return [str(Path(where) / n) for n in names]


def prepared(base=None, edit=None, user=(), where=OUT, write=None, links=None):
    """The set-up of a case, ``setup(work, bases) -> the user's files`` (the one builder of
    every case's folder): a copy of the earlier ``base`` ("run", "study", "sweep") as OUT,
    ``edit(OUT folder)`` applied to it, the user's own files ``user`` (names) made in ``where``,
    ``write`` = {path: bytes} files of the user's with that content and ``links`` = {path:
    target} symbolic links (paths relative to the case's folder)."""
    def setup(work, bases):
        made = []
        if base is not None:
            shutil.copytree(bases[base], work / OUT)
        if edit is not None:
            edit(work / OUT)
        if user:
            made += user_files(work, where, user)
        for name, content in (write or {}).items():
            (work / name).write_bytes(content)
            made.append(name)
        for name, target in (links or {}).items():
            os.symlink(work / target, work / name)
        return made
    return setup


def summary_check(status=None, steps=None, points=None):
    """verify(work): OUT's summary says ``status`` with ``steps`` steps done (and its final
    scalars), a sweep's ``points`` points completed; None when it does, else what is wrong."""
    def verify(work):
        try:
            s = json.loads((work / OUT / "summary.json").read_text())
        except (OSError, ValueError) as exc:
            return f"summary.json unreadable ({exc})"
        if status is not None and s.get("status") != status:
            return f"summary says {s.get('status')!r}, expected {status!r}"
        if steps is not None and (s.get("steps_done") != steps or not s.get("final")):
            return (f"summary says steps_done {s.get('steps_done')}, final "
                    f"{'set' if s.get('final') else 'null'}; {steps} steps are on disk")
        if points is not None and s.get("completed") != points:
            return f"sweep summary says completed {s.get('completed')}, expected {points}"
        return None
    return verify


def gmsh_mesh(path, kind):
    """A .msh file: 'ok' (unit square, cells tag 10, left edge 1, the others 2), 'notags'
    (no physical groups), 'tag1' (only the left edge tagged), '1d' (a line), '3d' (a cube)."""
    from damage_dolfinx.runtime.meshfile import _gmsh
    gmsh = _gmsh()  # the package's gmsh session (the tests run in one process)
    gmsh.model.add("m")
    occ = gmsh.model.occ
    if kind == "mixed":  # a triangle half and a quadrilateral half
        a, b = occ.addRectangle(0, 0, 0, 1, 1), occ.addRectangle(1, 0, 0, 1, 1)
        occ.fragment([(2, a)], [(2, b)])
        occ.synchronize()
        gmsh.model.mesh.setRecombine(2, b)
        curves = [t for _, t in gmsh.model.getEntities(1)]
        gmsh.model.addPhysicalGroup(2, [a, b], 10)
        gmsh.model.addPhysicalGroup(1, curves[:1], 1)
        gmsh.model.addPhysicalGroup(1, curves[1:], 2)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.25)
        gmsh.model.mesh.generate(2)
    elif kind == "1d":
        a, b = occ.addPoint(0, 0, 0), occ.addPoint(1, 0, 0)
        line = occ.addLine(a, b)
        occ.synchronize()
        gmsh.model.addPhysicalGroup(1, [line], 1)
        gmsh.model.mesh.generate(1)
    elif kind == "3d":
        box = occ.addBox(0, 0, 0, 1, 1, 1)
        occ.synchronize()
        gmsh.model.addPhysicalGroup(3, [box], 10)
        faces = [t for _, t in gmsh.model.getBoundary([(3, box)], oriented=False)]
        gmsh.model.addPhysicalGroup(2, faces[:1], 1)
        gmsh.model.addPhysicalGroup(2, faces[1:], 2)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
        gmsh.model.mesh.generate(3)
    else:
        rect = occ.addRectangle(0, 0, 0, 1, 1)
        occ.synchronize()
        if kind != "notags":
            gmsh.model.addPhysicalGroup(2, [rect], 10)
            curves = [t for _, t in gmsh.model.getBoundary([(2, rect)], oriented=False)]
            left = [c for c in curves
                    if abs(gmsh.model.occ.getCenterOfMass(1, c)[0]) < 1e-9]
            gmsh.model.addPhysicalGroup(1, left, 1)
            if kind == "ok":
                gmsh.model.addPhysicalGroup(1, [c for c in curves if c not in left], 2)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.25)
        gmsh.model.mesh.generate(2)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.write(str(path))
    gmsh.option.setNumber("Mesh.MeshSizeMax", 1e22)
    gmsh.model.remove()


def edit_checkpoint(path, change):
    """Rewrite checkpoint.npz with ``change(arrays, meta)`` applied."""
    with np.load(path) as data:
        arrays = {k: data[k] for k in data.files}
    meta = json.loads(str(arrays["__meta__"]))
    change(arrays, meta)
    arrays["__meta__"] = np.array(json.dumps(meta))
    with open(path, "wb") as f:
        np.savez(f, **arrays)


def _nan_zeta(arrays, meta):
    arrays["zeta"] = arrays["zeta"].copy()
    arrays["zeta"][len(arrays["zeta"]) // 2] = np.nan


def _short_zeta(arrays, meta):
    arrays["zeta"] = arrays["zeta"][:-3]


def _bad_step(arrays, meta):
    meta["step"] = -1


def _inf_u(arrays, meta):
    arrays["u"] = arrays["u"].copy()
    arrays["u"][0] = np.inf


# ---------------------------------------------------------------------------- the cases
#: (id, class, args (OUT is the folder), setup(work, bases) -> user files, expected outcome,
#:  fast: also in tests/test_bad_inputs.py)
def _cases():
    none = prepared()

    def copy(kind):
        return prepared(kind)

    def run_plus_user(names):
        return prepared("run", user=names)

    def study_plus_user(names):
        return prepared("study", user=names)

    def only_user(names):
        return prepared(user=names)

    def checkpoint_edit(change):
        return prepared("run", edit=lambda f: edit_checkpoint(f / "checkpoint.npz", change))

    def summary_text(text):
        return prepared("run", edit=lambda f: (f / "summary.json").write_text(text))

    def foreign_checkpoint(work, bases):
        shutil.copytree(bases["run"], work / OUT)
        shutil.copy(bases["run24"] / "checkpoint.npz", work / OUT / "checkpoint.npz")
        return []

    def mesh(kind):
        def setup(work, bases):
            gmsh_mesh(work / "m.msh", kind)
            return ["m.msh"]
        return setup

    def text_file(name, content):
        return prepared(write={name: content})

    def manifest_text(text):
        return prepared("run", edit=lambda f: (f / "manifest.json").write_text(text))

    out_is_file = prepared(write={OUT: b"the user's file\n"})

    tiny = ["--n", "5", "--k", "0.25", "--no-figures", "--quiet"]
    run = ["run", "2.1-ex1", *tiny]
    conv = ["converge", "2.1-ex1", "--ref-n", "10", "--ref-k", "0.125", "--quiet"]
    c = []

    def case(id_, cls, args, setup=none, expect="refused", fast=True, code=None, verify=None,
             ranks=1):
        c.append(dict(id=id_, cls=cls, args=args, setup=setup, expect=expect, fast=fast,
                      code=code, verify=verify, ranks=ranks))

    # -- 1. every option honoured or refused
    case("single-dash -n -k", "options", ["run", "2.1-ex1", "-n", "5", "-k", "0.5", "--out", OUT])
    case("unknown PETSc option -foo_bar", "options", [*run, "--out", OUT, "-foo_bar", "1"])
    case("PETSc bad value -mech_ksp_type", "options", [*run, "--out", OUT, "-mech_ksp_type",
                                                       "nonsense"])
    case("PETSc bad value -mech_ksp_rtol", "options", [*run, "--out", OUT, "-mech_ksp_rtol", "abc"])
    case("PETSc bad value -damage_pc_type", "options", [*run, "--out", OUT, "-damage_pc_type",
                                                        "nonsense"])
    case("PETSc bad value -damage_snes_type", "options", [*run, "--out", OUT,
                                                          "-damage_snes_type", "nonsense"])
    case("PETSc bad value -friction_ksp_max_it", "options",
         ["run", "2.2-ex1", "--n", "4", "--k", "0.25", "--T", "0.5", "--no-figures", "--quiet",
          "--out", OUT, "-friction_ksp_max_it", "1.5"])
    case("single-dash -h (mesh size)", "options", ["run", "2.1-ex2a", "-h", "0.5", "--out", OUT])
    case("single-dash -T", "options", [*run, "-T", "2", "--out", OUT])
    case("single-dash -out", "options", [*run, "-out", OUT])
    case("single-dash -set", "options", [*run, "-set", "kappa=2", "--out", OUT])
    case("misspelt --nn", "options", [*run, "--nn", "5", "--out", OUT])
    case("misspelt --overwite", "options", [*run, "--overwite", "--out", OUT])
    case("stray word", "options", [*run, "extra", "--out", OUT])
    case("--n not a number", "options", ["run", "2.1-ex1", "--n", "abc", "--out", OUT])
    case("--n not whole", "options", ["run", "2.1-ex1", "--n", "2.5", "--out", OUT])
    case("unknown --reading", "options", [*run, "--reading", "bogus", "--out", OUT])
    case("unknown --friction-solver", "options", [*run, "--friction-solver", "bogus", "--out",
                                                  OUT])
    case("--set without =", "options", [*run, "--set", "kappa", "--out", OUT])
    case("converge single-dash -n", "options", [*conv, "-n", "5", "--k", "0.25", "--out", OUT])
    case("converge unknown PETSc option", "options", [*conv, "--n", "5", "--k", "0.25", "--out",
                                                      OUT, "-bogus_option"])
    case("no solver reads -mech_foo", "options", [*run, "--out", OUT, "-mech_foo", "1"],
         expect="warned")
    case("no friction solver in 2.1", "options", [*run, "--out", OUT, "-friction_ksp_type",
                                                  "cg"], expect="warned")
    case("a PETSc option that is used", "options", [*run, "--out", OUT, "-mech_ksp_rtol",
                                                    "1e-10"], expect="ok")
    case("list with a stray option", "options", ["list", "-x"])
    # -- 1. numeric ranges
    case("--k 1e-12 (1e12 steps)", "ranges", ["run", "2.1-ex1", "--k", "1e-12", "--out", OUT])
    case("--T 1e9 (1e11 steps)", "ranges", ["run", "2.1-ex1", "--T", "1e9", "--out", OUT])
    case("--write-every 0", "ranges", [*run, "--write-every", "0", "--out", OUT])
    case("--write-every -3", "ranges", [*run, "--write-every", "-3", "--out", OUT])
    case("--checkpoint-every 0", "ranges", [*run, "--checkpoint-every", "0", "--out", OUT])
    case("--checkpoint-every -1", "ranges", [*run, "--checkpoint-every", "-1", "--out", OUT])
    case("--checkpoint-seconds -1", "ranges", [*run, "--checkpoint-seconds", "-1", "--out", OUT])
    case("--checkpoint-seconds inf", "ranges", [*run, "--checkpoint-seconds", "inf", "--out",
                                                OUT])
    case("--history-every -1", "ranges", [*run, "--history-every", "-1", "--out", OUT])
    case("--n -5", "ranges", ["run", "2.1-ex1", "--n", "-5", "--out", OUT])
    case("--h -0.1", "ranges", ["run", "2.1-ex2a", "--h", "-0.1", "--out", OUT])
    case("--T -1", "ranges", ["run", "2.1-ex1", "--T", "-1", "--out", OUT])
    case("--k nan", "ranges", ["run", "2.1-ex1", "--k", "nan", "--out", OUT])
    case("converge --n 0 5", "ranges", [*conv, "--n", "0", "5", "--k", "0.25", "--out", OUT])
    case("converge --n 5 5", "ranges", [*conv, "--n", "5", "5", "--k", "0.25", "--out", OUT])
    case("converge --k 0.25 0.25", "ranges", [*conv, "--n", "5", "--k", "0.25", "0.25", "--out",
                                              OUT])
    case("converge --k -0.25", "ranges", [*conv, "--n", "5", "--k", "-0.25", "--out", OUT])
    case("converge --ref-n 0", "ranges", ["converge", "2.1-ex1", "--ref-n", "0", "--n", "5",
                                          "--out", OUT])
    case("converge --ref-k 1e-12", "ranges", ["converge", "2.1-ex1", "--ref-k", "1e-12", "--k",
                                              "0.01", "--out", OUT])
    case("converge --n coarser than ref", "ranges", [*conv, "--n", "20", "--k", "0.25", "--out",
                                                     OUT])
    case("converge --n not nested", "ranges", [*conv, "--n", "3", "--k", "0.25", "--out", OUT])
    # -- 2. nothing the user made is deleted or overwritten
    case("--overwrite beside the user's fields_keep_for_paper.*", "folder",
         [*run, "--overwrite", "--out", OUT],
         run_plus_user(["fields_keep_for_paper.h5", "fields_keep_for_paper.xdmf"]), "ok")
    case("user's history.csv, fields.h5, fields_final.npz, no summary", "folder",
         [*run, "--out", OUT],
         only_user(["history.csv", "fields.h5", "fields_final.npz"]))
    case("the same with --overwrite", "folder", [*run, "--overwrite", "--out", OUT],
         only_user(["history.csv", "fields.h5", "fields_final.npz"]))
    case("a folder of the user's notes, no manifest", "folder", [*run, "--out", OUT],
         only_user(["notes.txt"]))
    case("user's own summary.json", "folder", [*run, "--overwrite", "--out", OUT],
         only_user(["summary.json"]))
    case("run into a finished run (no flag)", "folder", [*run, "--out", OUT], copy("run"))
    case("--out is the user's file", "folder", [*run, "--out", OUT], out_is_file)
    case("--restart in an empty folder", "folder", [*run, "--restart", "--out", OUT])
    case("converge into a study (no flag)", "folder", [*conv, "--n", "5", "--k", "0.25", "0.5",
                                                       "--out", OUT], copy("study"))
    case("converge into a run", "folder", [*conv, "--n", "5", "--k", "0.25", "--out", OUT],
         copy("run"))
    case("converge --overwrite into a run", "folder", [*conv, "--n", "5", "--k", "0.25",
                                                       "--overwrite", "--out", OUT], copy("run"))
    case("run into a study", "folder", [*run, "--out", OUT], copy("study"))
    case("run --overwrite into a study", "folder", [*run, "--overwrite", "--out", OUT],
         copy("study"))
    case("converge --restart of a finished study", "folder",
         [*conv, "--n", "5", "--k", "0.25", "0.5", "--restart", "--out", OUT], copy("study"),
         "ok")
    case("converge --restart, other levels", "folder",
         [*conv, "--n", "5", "--k", "0.5", "--restart", "--out", OUT], copy("study"))
    case("converge --overwrite beside the user's file", "folder",
         [*conv, "--n", "5", "--k", "0.25", "0.5", "--overwrite", "--out", OUT],
         study_plus_user(["errors_by_hand.csv"]), "ok", fast=False)
    case("manifest.json damaged", "folder", [*run, "--overwrite", "--out", OUT],
         manifest_text("{not json"))
    case("manifest.json lists a path outside", "folder", [*run, "--overwrite", "--out", OUT],
         manifest_text('{"schema": "damage-dolfinx/manifest/v1", "kind": "run", '
                       '"files": ["../x"]}'))
    # -- 3. everything read from disk is validated
    case("checkpoint with a NaN in zeta, --restart --T 2", "disk",
         [*run, "--T", "2", "--restart", "--out", OUT], checkpoint_edit(_nan_zeta))
    case("checkpoint with an Inf in u, --restart --T 2", "disk",
         [*run, "--T", "2", "--restart", "--out", OUT], checkpoint_edit(_inf_u))
    case("checkpoint with zeta 3 values short", "disk",
         [*run, "--T", "2", "--restart", "--out", OUT], checkpoint_edit(_short_zeta))
    case("checkpoint at step -1", "disk", [*run, "--T", "2", "--restart", "--out", OUT],
         checkpoint_edit(_bad_step))
    case("checkpoint of another example", "disk", [*run, "--T", "2", "--restart", "--out", OUT],
         foreign_checkpoint)
    case("--restart with other parameters", "disk",
         [*run, "--T", "2", "--set", "E=2e4", "--restart", "--out", OUT], copy("run"))
    case("--restart with another n", "disk",
         ["run", "2.1-ex1", "--n", "10", "--k", "0.25", "--T", "2", "--no-figures", "--quiet",
          "--restart", "--out", OUT], copy("run"))
    case("summary.json truncated, run into it", "disk", [*run, "--out", OUT],
         summary_text('{"schema": "damage-dolfinx/summary/v1", "sta'))
    case("summary.json truncated, --restart --T 2 (the checkpoint continues)", "disk",
         [*run, "--T", "2", "--restart", "--out", OUT],
         summary_text('{"schema": "damage-dolfinx/summary/v1", "sta'), "ok")
    case("summary.json with steps_done 'abc', --restart", "disk",
         [*run, "--restart", "--out", OUT],
         summary_text('{"schema": "damage-dolfinx/summary/v1", "status": "completed", '
                      '"steps_done": "abc", "t_final": 1}'), "ok")
    case("--mesh empty file", "mesh", ["run", "2.1-ex2a", "--mesh", "m.msh", "--out", OUT],
         text_file("m.msh", b""))
    case("--mesh text file", "mesh", ["run", "2.1-ex2a", "--mesh", "m.msh", "--out", OUT],
         text_file("m.msh", b"this is not a mesh\n"))
    case("--mesh truncated header", "mesh", ["run", "2.1-ex2a", "--mesh", "m.msh", "--out", OUT],
         text_file("m.msh", b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n12 3"))
    case("--mesh 1-D mesh", "mesh", ["run", "2.1-ex2a", "--mesh", "m.msh", "--out", OUT],
         mesh("1d"))
    case("--mesh 3-D mesh", "mesh", ["run", "2.1-ex2a", "--mesh", "m.msh", "--out", OUT],
         mesh("3d"))
    case("--mesh without physical groups", "mesh",
         ["run", "2.1-ex2a", "--mesh", "m.msh", "--out", OUT], mesh("notags"))
    case("--mesh without the Gamma_N tag", "mesh",
         ["run", "2.1-ex2a", "--mesh", "m.msh", "--out", OUT], mesh("tag1"))
    case("--mesh for a 3-D example", "mesh", ["run", "2.1-ex1-3d", "--mesh", "m.msh", "--out",
                                              OUT], mesh("ok"))
    case("--mesh is a folder", "mesh", ["run", "2.1-ex2a", "--mesh", ".", "--out", OUT])
    case("--mesh a good mesh (control)", "mesh",
         ["run", "2.1-ex2a", "--mesh", "m.msh", "--k", "0.25", "--T", "0.5", "--no-figures",
          "--quiet", "--out", OUT], mesh("ok"), "ok", fast=False)
    # -- 4. non-finite or absurd states stop the run
    case("2.2-ex1 --set E=1e-12 (factorisation fails)", "state",
         ["run", "2.2-ex1", "--n", "4", "--k", "0.02", "--no-figures", "--quiet",
          "--set", "E=1e-12", "--out", OUT], expect="failed")
    case("--set lam_u_plus=1e300", "state", [*run, "--set", "lam_u_plus=1e300", "--out", OUT],
         expect="failed")
    case("variant A, --set lam_u=1e300", "state",
         [*run, "--set", "variant=A", "--set", "lam_u=1e300", "--out", OUT], expect="failed")
    case("--set lam_u_minus=1e300 (2.1-ex2b)", "state",
         ["run", "2.1-ex2b", "--h", "1", "--k", "0.25", "--T", "0.5", "--no-figures", "--quiet",
          "--set", "lam_u_minus=1e300", "--out", OUT], expect="failed", fast=False)
    case("--set q_star=1e300 --set lam_u_plus=1e300", "state",
         [*run, "--set", "q_star=1e300", "--set", "lam_u_plus=1e300", "--out", OUT],
         expect="failed")
    case("--set E=1e300 (a rigid body: a valid run)", "state", [*run, "--set", "E=1e300",
                                                               "--out", OUT], expect="ok")
    case("2.4-ex1 --set E=1e-300", "state",
         ["run", "2.4-ex1", "--n", "4", "--k", "0.25", "--T", "0.5", "--no-figures", "--quiet",
          "--set", "E=1e-300", "--out", OUT], expect="failed", fast=False)
    # -- 5. strict JSON
    case("one-level converge (rates without a value)", "json",
         [*conv, "--n", "5", "--k", "0.25", "--out", OUT], expect="ok", fast=False)
    # -- the stability check of 3.3-ex1: a chosen k above k_max is refused (--allow-unstable)
    case("3.3-ex1 at k = 3.1 k_max", "ranges",
         ["run", "3.3-ex1", "--n", "8", "--k", "3.5", "--T", "7", "--no-figures", "--quiet",
          "--out", OUT], fast=False)
    sweep_base = ["sweep", "2.1-ex1", "--n", "5", "--k", "0.25", "--no-figures", "--quiet"]
    _api_cases(case, none, copy, only_user, mesh, run, conv, sweep_base)
    return c


# ---------------------------------------------------------------------------- the API, sweeps,
# converge, restarts and MPI
#: what every API case starts from (a tiny 2.1 problem of one's own: 2 steps on 8 x 2 cells)
API_PRELUDE = '''
import sys
import numpy as np
import ufl
from mpi4py import MPI
import damage_dolfinx as dd
from damage_dolfinx.geometries.rectangle import rectangle, side


def mesh(comm, n):
    return rectangle(comm, (0.0, 0.0), (2.0, 0.5), 4 * n, n,
                     {1: side(0, 0.0), 2: side(0, 2.0), 3: side(1, 0.0)})


def problem(**changes):
    data = dict(model="2.1", mesh=mesh, n=2, T=0.02, k=0.01,
                boundaries={"clamped": 1, "traction": 2, "bilateral": 3},
                traction=lambda x, t: ufl.as_vector((10.0 * t, 0.0)))
    data.update(changes)
    return dd.Problem(**data)


def run(p, out="o", **kw):
    kw.setdefault("figures", False)
    kw.setdefault("progress", False)
    return dd.run(p, out, **kw)
'''

#: runs a case's code as a user's script would, the exceptions of the API mapped to the command
#: line's exit statuses (rank 0 prints the one line); any other exception is a traceback
API_HARNESS = '''
import sys
from mpi4py import MPI
from damage_dolfinx.core.parameters import InputError
from damage_dolfinx.numerics.solvers import ConvergenceError
from damage_dolfinx.runtime.io import OutputError
CODE = open(sys.argv[1]).read()
say = (lambda text: print(text, file=sys.stderr, flush=True)) if MPI.COMM_WORLD.rank == 0 \\
    else (lambda text: None)
try:
    exec(compile(CODE, "case.py", "exec"), {"__name__": "__main__"})
except InputError as exc:
    say(f"damage-dolfinx: error: {exc}")
    sys.exit(2)
except (ConvergenceError, OutputError) as exc:
    say(f"damage-dolfinx: failed: {exc}")
    sys.exit(3 if isinstance(exc, ConvergenceError) else 4)
except Exception as exc:
    if hasattr(exc, "exit_status"):
        say(f"damage-dolfinx: {exc}")
        sys.exit(exc.exit_status)
    raise
'''


def _api_cases(case, none, copy, only_user, mesh, run, conv, sweep_base):
    def api(id_, cls, code, expect="refused", setup=none, fast=True, verify=None, ranks=1,
            first=None):
        if first is not None:  # an earlier run of the API, made before the case
            def setup(work, bases, code=API_PRELUDE + first):
                status, err = _api_in_process(code, work)
                if status != 0:
                    raise RuntimeError(f"the earlier run of the case failed: {err}")
                return []
        case(id_, cls, ["<api>"], setup, expect, fast, code=API_PRELUDE + code, verify=verify,
             ranks=ranks)

    # -- the API's bad input (validation.py): refused before any file, naming the argument
    api("traction with 3 components on a 2-D mesh", "api",
        "run(problem(traction=lambda x, t: ufl.as_vector((t, 0.0, 0.0))))")
    api("scalar traction", "api", "run(problem(traction=lambda x, t: 5.0 * t))")
    api("traction as a tuple", "api", "run(problem(traction=lambda x, t: (t, 0.0)))")
    api("body force with 3 components", "api",
        "run(problem(body_force=lambda x, t: ufl.as_vector((t, 0.0, 0.0))))")
    api("traction not callable", "api", "run(problem(traction=5.0))")
    api("damage law returning a vector", "api",
        "run(problem(damage_law=dd.DamageLaw(lambda e, z, p: ufl.as_vector((z, z)))))")
    api("damage law returning text", "api",
        "run(problem(damage_law=dd.DamageLaw(lambda e, z, p: 'fast')))")
    api("damage law using NumPy on UFL", "api",
        "run(problem(damage_law=dd.DamageLaw(lambda e, z, p: np.sqrt(z))))")
    api("damage_law a bare function", "api", "run(problem(damage_law=lambda e, z, p: z))")
    api("params E=[...]", "api", "run(problem(params={'E': [1.0, 2.0]}))")
    api("params E='abc'", "api", "run(problem(params={'E': 'abc'}))")
    api("params E=-1", "api", "run(problem(params={'E': -1.0}))")
    api("params nu=0.7", "api", "run(problem(params={'nu': 0.7}))")
    api("params a text", "api", "run(problem(params='E=5'))")
    api("model_defaults('3.3') to a 2.1 problem", "api",
        "run(problem(params=dd.model_defaults('3.3')))")
    api("model_defaults('2.2') to a 2.1 problem", "api",
        "run(problem(model='2.4', boundaries={'clamped': 1, 'traction': 2, 'tresca': 3}, "
        "params=dd.model_defaults('2.2')))")
    api("traction but no traction role", "api",
        "run(problem(boundaries={'clamped': 1, 'bilateral': 3}))")
    api("irreversible='no'", "api", "run(problem(irreversible='no'))")
    api("allow_unstable='yes'", "api", "run(problem(allow_unstable='yes'))")
    api("zeta0=1.5", "api", "run(problem(zeta0=1.5))")
    api("zeta0='abc'", "api", "run(problem(zeta0='abc'))")
    api("zeta0(x) outside [zeta*, 1]", "api", "run(problem(zeta0=lambda x: 2.0 + 0 * x[0]))")
    api("zeta0(x) of the wrong shape", "api",
        "run(problem(zeta0=lambda x: np.ones((2, x.shape[1]))))")
    api("k negative", "api", "run(problem(k=-0.01))")
    api("k above T", "api", "run(problem(k=0.5))")
    api("T=nan", "api", "run(problem(T=float('nan')))")
    api("T=0", "api", "run(problem(T=0))")
    api("T=1e-300 below k (zero steps)", "api", "run(problem(T=1e-300))")
    api("n=2.5", "api", "run(problem(n=2.5))")
    api("n=0", "api", "run(problem(n=0))")
    api("mesh family without n", "api", "run(problem(n=None))")
    api("model '9.9'", "api", "run(problem(model='9.9'))")
    api("model 2.1 (a float)", "api", "run(problem(model=2.1))")
    api("boundaries {'clamped': 'left'}", "api",
        "run(problem(boundaries={'clamped': 'left', 'traction': 2}))")
    api("boundary role unknown", "api",
        "run(problem(boundaries={'glued': 1, 'traction': 2}))")
    api("boundary tag not on the mesh", "api",
        "run(problem(boundaries={'clamped': 7, 'traction': 2}))")
    api("name with a slash", "api", "run(problem(name='a/b'))")
    api("mesh=42", "api", "run(problem(mesh=42, n=None))")
    api("mesh a missing file", "api", "run(problem(mesh='missing.msh', n=None))")
    api("mesh a folder", "api", "run(problem(mesh='.', n=None))")
    api("T=np.int64(1) (a NumPy number)", "api",
        "run(problem(T=np.int64(1), k=np.float64(0.25)))", expect="ok", fast=False)
    api("params E=np.float64 (a NumPy number)", "api",
        "run(problem(params={'E': np.float64(2e4)}))", expect="ok", fast=False)
    api("run(out=None)", "api", "run(problem(), out=None)")
    api("run(restart='yes')", "api", "run(problem(), restart='yes')")
    api("run(checkpoint_every=0)", "api", "run(problem(), checkpoint_every=0)")
    api("run(n=-1)", "api", "run(problem(), n=-1)")
    api("converge(n=2)", "api",
        "dd.converge(problem(), 'o', n=2, k=[0.01], ref_n=4, ref_k=0.005)")
    api("converge(k=0.01)", "api",
        "dd.converge(problem(), 'o', n=[2], k=0.01, ref_n=4, ref_k=0.005)")
    api("converge(ref_n=2.5)", "api",
        "dd.converge(problem(), 'o', n=[2], k=[0.01], ref_n=2.5, ref_k=0.005)")
    api("converge(n=[0])", "api",
        "dd.converge(problem(), 'o', n=[0], k=[0.01], ref_n=4, ref_k=0.005)")
    api("sweep(max_points=0)", "api", "dd.sweep(problem(), 'o', {'kappa': [1.0]}, max_points=0)")
    api("sweep(figures='no')", "api", "dd.sweep(problem(), 'o', {'kappa': [1.0]}, figures='no')")
    api("read_mesh of a folder", "api", "dd.read_mesh('.')")
    api("read_mesh(42)", "api", "dd.read_mesh(42)")
    api("read_mesh(dim=5)", "api", "dd.read_mesh('m.msh', dim=5)", setup=mesh("ok"))
    api("read_mesh of a mixed triangle/quad file", "api", "dd.read_mesh('m.msh')",
        setup=mesh("mixed"))
    api("from_gmsh(dim=5)", "api", "dd.from_gmsh(dim=5)")
    # -- restarts: a fingerprint of what defines the run, checked by every resume
    first = "run(problem(T=0.02), checkpoint_every=1)\n"
    api("restart with a traction 100 times larger", "restart", first=first, code=
        "run(problem(T=0.04, traction=lambda x, t: ufl.as_vector((1000.0 * t, 0.0))), "
        "restart=True)", fast=False)
    api("restart with another damage law", "restart", first=first, code=
        "run(problem(T=0.04, damage_law=dd.DamageLaw(lambda e, z, p: -z, 'own')), "
        "restart=True)", fast=False)
    api("restart with irreversibility on", "restart", first=first, code=
        "run(problem(T=0.04, irreversible=True), restart=True)", fast=False)
    api("restart with the boundary parts swapped", "restart", first=first, code=
        "run(problem(T=0.04, boundaries={'clamped': 2, 'traction': 1, "
        "'bilateral': 3}), restart=True)", fast=False)
    api("restart with a body force added", "restart", first=first, code=
        "run(problem(T=0.04, body_force=lambda x, t: ufl.as_vector((0.0, -t))), "
        "restart=True)", fast=False)
    api("restart with zeta0 changed", "restart", first=first, code=
        "run(problem(T=0.04, zeta0=0.5), restart=True)", fast=False)
    api("restart, the same problem to a larger T (control)", "restart", first=first, code=
        "s = run(problem(T=0.04), restart=True)\nassert s['steps_done'] == 4, s",
        expect="ok", fast=False)

    def steps_done(n):
        return summary_check("completed", n)

    def cut_summary(folder):
        text = (folder / "summary.json").read_text()
        (folder / "summary.json").write_text(text[:len(text) // 3])

    def zero_summary(folder):
        s = json.loads((folder / "summary.json").read_text())
        s.update(status="failed", error="cannot write fields_final.png: No space left on device")
        (folder / "summary.json").write_text(json.dumps(s))

    summary_cut = prepared("run", edit=cut_summary)
    summary_zero = prepared("run", edit=zero_summary)

    case("completed run, summary.json cut short, --restart", "restart",
         [*run, "--restart", "--out", OUT], summary_cut, "ok", verify=steps_done(4))
    case("run failed at its last figure (disk full), --restart", "restart",
         [*run, "--restart", "--out", OUT], summary_zero, "ok", verify=steps_done(4))
    case("--restart --reading evidence of a literal run", "restart",
         [*run, "--T", "2", "--reading", "evidence", "--restart", "--out", OUT], copy("run"))
    # -- zero steps and time grids
    case("--T 1e-300 (zero steps)", "ranges", ["run", "2.1-ex1", "--n", "5", "--T", "1e-300",
                                                "--out", OUT])
    case("converge --T 1e-300", "ranges", [*conv, "--n", "5", "--k", "0.25", "--T", "1e-300",
                                           "--out", OUT])
    case("sweep --T 1e-300", "sweep", [*sweep_base, "--T", "1e-300", "--set", "kappa=1,2",
                                       "--out", OUT])
    # -- sweeps under the run-folder rules
    case("sweep into a finished run", "sweep", [*sweep_base, "--set", "kappa=1,2", "--out", OUT],
         copy("run"))
    case("sweep into a convergence study", "sweep",
         [*sweep_base, "--set", "kappa=1,2", "--out", OUT], copy("study"))
    case("sweep into a folder of the user's notes", "sweep",
         [*sweep_base, "--set", "kappa=1,2", "--out", OUT], only_user(["notes.txt"]))
    case("sweep with a user's file in point_1/", "sweep",
         [*sweep_base, "--set", "kappa=1,2", "--out", OUT], point_user_file)
    case("run into a sweep folder", "sweep", [*run, "--out", OUT], copy("sweep"))
    case("run --overwrite into a sweep folder", "sweep", [*run, "--overwrite", "--out", OUT],
         copy("sweep"))
    case("converge into a sweep folder", "sweep",
         [*conv, "--n", "5", "--k", "0.25", "--out", OUT], copy("sweep"))
    case("sweep of 9e6 points", "sweep",
         [*sweep_base, "--set", "kappa=" + ",".join(str(i + 1) for i in range(3000)),
          "--set", "lam_D=" + ",".join(str(0.001 * (i + 1)) for i in range(3000)),
          "--out", OUT])
    case("sweep --max-points 0", "sweep", [*sweep_base, "--set", "kappa=1,2", "--max-points",
                                           "0", "--out", OUT])
    case("sweep --set kappa=nan", "sweep", [*sweep_base, "--set", "kappa=1,nan", "--out", OUT])
    case("sweep unknown parameter", "sweep", [*sweep_base, "--set", "bogus=1,2", "--out", OUT])
    case("sweep with a failing point", "sweep",
         [*sweep_base, "--set", "lam_u_plus=1,1e300", "--out", OUT], expect="failed",
         fast=False)
    case("sweep into a folder named by a dangling link", "sweep",
         [*sweep_base, "--set", "kappa=1,2", "--out", OUT], dangling)
    # -- a non-finite damage source fails the run on every model, whatever the solver path
    case("2.2-ex1 --set lam_u=1e300 (obstacle damage step)", "state",
         ["run", "2.2-ex1", "--n", "4", "--k", "0.02", "--T", "0.1", "--no-figures", "--quiet",
          "--set", "lam_u=1e300", "--out", OUT], expect="failed", fast=False)
    case("2.4-ex1 --set lam_u=1e300 (obstacle damage step)", "state",
         ["run", "2.4-ex1", "--n", "4", "--k", "0.25", "--T", "0.5", "--no-figures", "--quiet",
          "--set", "lam_u=1e300", "--out", OUT], expect="failed", fast=False)
    # -- mesh files and weak messages
    case("--mesh mixed triangles and quadrilaterals", "mesh",
         ["run", "2.1-ex2a", "--mesh", "m.msh", "--out", OUT], mesh("mixed"))
    case("--out a dangling symbolic link", "folder", [*run, "--out", OUT], dangling)
    case("--out a symbolic link loop", "folder", [*run, "--out", OUT], link_loop)
    # -- MPI: a refusal or a failure on one rank ends every rank, one line
    case("2 ranks: sweep with a user's file in point_1/", "mpi",
         [*sweep_base, "--set", "kappa=1,2", "--out", OUT], point_user_file, fast=False,
         ranks=2)
    case("2 ranks: sweep of 9e6 points", "mpi",
         [*sweep_base, "--set", "kappa=" + ",".join(str(i + 1) for i in range(3000)),
          "--set", "lam_D=" + ",".join(str(0.001 * (i + 1)) for i in range(3000)),
          "--out", OUT], fast=False, ranks=2)
    case("2 ranks: --mesh mixed cell types", "mpi",
         ["run", "2.1-ex2a", "--mesh", "m.msh", "--out", OUT], mesh("mixed"), fast=False,
         ranks=2)
    api("2 ranks: a load raising on rank 1 only", "mpi",
        "def load(x, t):\n    if MPI.COMM_WORLD.rank == 1:\n        raise RuntimeError('rank 1')\n"
        "    return ufl.as_vector((t, 0.0))\nrun(problem(traction=load))", fast=False, ranks=2)
    api("2 ranks: a damage law raising on rank 1 at set-up", "mpi",
        "calls = []\ndef law(e, z, p):\n    calls.append(1)\n"
        "    if MPI.COMM_WORLD.rank == 1 and len(calls) > 1:\n        raise ZeroDivisionError('r1')\n"
        "    return -z\nrun(problem(damage_law=dd.DamageLaw(law, 'own')))", fast=False, ranks=2)
    api("2 ranks: a traction of 3 components", "mpi",
        "run(problem(traction=lambda x, t: ufl.as_vector((t, 0.0, 0.0))))", fast=False, ranks=2)
    api("3 ranks: a load raising on rank 1 only", "mpi",
        "def load(x, t):\n    if MPI.COMM_WORLD.rank == 1:\n        raise RuntimeError('rank 1')\n"
        "    return ufl.as_vector((t, 0.0))\nrun(problem(traction=load))", fast=False, ranks=3)
    import importlib.util
    spec = importlib.util.spec_from_file_location("bad_inputs_more", HERE / "bad_inputs_more.py")
    more = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(more)
    more.more_cases(case, api, globals(), none, copy, only_user, mesh, run, conv, sweep_base)


#: the sweep with the user's notes in point_1/ (a folder of theirs where a point's would be)
point_user_file = prepared("sweep", edit=lambda f: shutil.rmtree(f / "point_1"),
                           user=["notes.txt"], where=f"{OUT}/point_1")
#: OUT a dangling symbolic link, and a link to itself
dangling = prepared(links={OUT: "nowhere"})
link_loop = prepared(links={OUT: OUT})


CASES = _cases()


# ---------------------------------------------------------------------------- running
def make_bases(root: Path, runner) -> dict:
    """The earlier run (2.1-ex1 and 2.4-ex1) and study the folder cases start from."""
    bases = {"run": root / "base_run", "run24": root / "base_run24", "study": root / "base_study"}
    runner([*RUN, "--out", str(bases["run"])], root)
    runner(["run", "2.4-ex1", "--n", "4", "--k", "0.25", "--T", "0.5", "--no-figures",
            "--quiet", "--out", str(bases["run24"])], root)
    runner([*STUDY, "--out", str(bases["study"])], root)
    bases["sweep"] = root / "base_sweep"
    runner([*SWEEP, "--out", str(bases["sweep"])], root)
    return bases


#: seconds a case may take (a case still running then counts as "no end")
TIMEOUT = [300]
#: the same under mpirun (a rank waiting for another that failed is the hang looked for)
MPI_TIMEOUT = 60


def _subprocess(args, cwd, ranks=1, script=None):
    """The command line (or, with ``script``, the API harness on the case's code) in ``cwd``,
    under mpirun with ``ranks`` > 1 (a job still running after the timeout is a hang)."""
    command = [sys.executable, *(script or ["-m", "damage_dolfinx.cli", *args])]
    if ranks > 1:
        command = ["mpirun", "-n", str(ranks), *command]
    timeout = TIMEOUT[0] if ranks == 1 else min(TIMEOUT[0], MPI_TIMEOUT)
    try:
        proc = subprocess.run(command, cwd=cwd, env=ENV, capture_output=True, text=True,
                              timeout=timeout)
    except subprocess.TimeoutExpired as exc:
        err = exc.stderr.decode(errors="replace") if isinstance(exc.stderr, bytes) else \
            (exc.stderr or "")
        return None, "", err
    return proc.returncode, proc.stdout, proc.stderr


def snapshot(work: Path) -> dict:
    """name (relative to the case's folder) -> sha256 of every file (but the run lock
    ``.lock``, the package's bookkeeping, which a job ended by MPI_Abort leaves behind: it
    never blocks a later run)."""
    out = {}
    for path in sorted(work.rglob("*")):
        if path.is_file() and path.name != ".lock":
            out[str(path.relative_to(work))] = hashlib.sha256(path.read_bytes()).hexdigest()
    return out


def classify(case, status, stderr, before, after, user, work) -> dict:
    lines = [line for line in stderr.splitlines() if line.strip()]
    ours = [line for line in lines if line.startswith("damage-dolfinx:") or
            line.startswith("WARNING:")]
    touched = sorted(f for f in user if before.get(f) != after.get(f))
    bad_json = []  # the JSON files the case wrote (a user's broken file is the case itself)
    for name in after:
        if name.endswith(".json") and before.get(name) != after[name]:
            try:
                _strict((work / name).read_text())
            except ValueError as exc:
                bad_json.append(f"{name}: {exc}")
    changed = sorted(f for f in set(before) | set(after) if before.get(f) != after.get(f))
    summary = {}
    try:
        summary = _strict((work / OUT / "summary.json").read_text())
    except (OSError, ValueError):
        pass
    if status is None:
        outcome = f"no end within {TIMEOUT[0]} s"
    elif "Traceback" in stderr or status not in (0, 2, 3, 4, 130, 143):
        outcome = "traceback or crash"
    elif touched:
        outcome = "user file touched"
    elif bad_json:
        outcome = "invalid JSON"
    elif status == 2 and len(ours) == 1 and not changed:
        outcome = "refused"
    elif status == 3 and len(ours) == 1 and summary.get("status") == "failed" and \
            summary.get("error"):
        outcome = "failed"
    elif status in (130, 143) and len(ours) == 1 and summary.get("status", "interrupted") \
            in ("interrupted", "stopped"):
        outcome = "interrupted"
    elif status == 0 and any("warning" in line.lower() for line in ours):
        outcome = "warned"
    elif status == 0:
        outcome = "ok"
    else:
        outcome = f"other (exit {status}, {len(ours)} line(s), {len(changed)} file(s) changed)"
    message = ours[0] if ours else (lines[0] if lines else "")
    return {"id": case["id"], "class": case["cls"],
            "command": (f"mpirun -n {case['ranks']} " if case.get("ranks", 1) > 1 else "")
            + ("python (API): " + case["code"].split("return dd.run(p, out, **kw)\n")[-1].strip()
               if case.get("code") else "damage-dolfinx " + " ".join(
                   a if len(a) < 60 else a[:40] + "..." for a in case["args"])),
            "exit_status": status,
            "message": message, "files_before": sorted(before), "files_after": sorted(after),
            "user_files_touched": touched, "invalid_json": bad_json, "outcome": outcome,
            "expected": case["expect"], "pass": outcome == case["expect"]}


def _api_in_process(code, cwd):
    """(exit status, stderr) of the API harness run on ``code`` in this process (the tests)."""
    import contextlib
    import io
    import traceback
    err, here = io.StringIO(), os.getcwd()
    os.chdir(cwd)
    try:
        with contextlib.redirect_stderr(err):
            try:
                exec(compile(API_HARNESS.replace("CODE = open(sys.argv[1]).read()",
                                                 "CODE = _CODE"), "harness.py", "exec"),
                     {"__name__": "__main__", "_CODE": code})
                status = 0
            except SystemExit as exc:  # as the interpreter maps it: None 0, a text 1
                status = exc.code if isinstance(exc.code, int) else int(exc.code is not None)
            except Exception:  # noqa: BLE001 - recorded as a traceback
                err.write(traceback.format_exc())
                status = 1
    finally:
        os.chdir(here)
    return status, err.getvalue()


def run_case(case, bases, root: Path, runner=_subprocess) -> dict:
    """One case in a folder of its own under ``root``. ``runner(args, cwd)`` runs the command
    line (tests: in the test's process); the API cases and the MPI cases always run in a
    process of their own (a hang must not stop the table)."""
    work = Path(tempfile.mkdtemp(dir=root))
    user = case["setup"](work, bases)
    before = snapshot(work)
    start = time.perf_counter()
    if case.get("code") is not None and case.get("ranks", 1) == 1 and runner is not _subprocess:
        status, stderr = _api_in_process(case["code"], work)
    elif case.get("code") is not None:
        scripts = Path(tempfile.mkdtemp(dir=root))
        (scripts / "harness.py").write_text(API_HARNESS)
        (scripts / "case.py").write_text(case["code"])
        status, _, stderr = _subprocess(None, work, case.get("ranks", 1),
                                        [str(scripts / "harness.py"), str(scripts / "case.py")])
    elif case.get("ranks", 1) > 1:
        status, _, stderr = _subprocess(case["args"], work, case["ranks"])
    else:
        status, _, stderr = runner(case["args"], work)
    result = classify(case, status, stderr, before, snapshot(work), user, work)
    if result["outcome"] == "ok" and case.get("verify"):
        wrong = case["verify"](work)
        if wrong:
            result.update(outcome="silently wrong result", message=wrong,
                          **{"pass": case["expect"] == "silently wrong result"})
    result["seconds"] = round(time.perf_counter() - start, 1)
    shutil.rmtree(work, ignore_errors=True)
    return result


def kind(r) -> str:
    """The case's result in the classes of defects looked for: clean (the expected outcome),
    hang, traceback or crash, silently wrong result or ignored input (a run that completed
    where a refusal or a failure was due, or a wrong summary), user file lost or overwritten,
    other."""
    if r["pass"]:
        return "clean"
    if r["outcome"].startswith("no end"):
        return "hang"
    if r["outcome"] in ("traceback or crash", "user file touched"):
        return {"user file touched": "user file lost or overwritten"}.get(r["outcome"],
                                                                          r["outcome"])
    if r["outcome"] in ("ok", "warned", "silently wrong result"):
        return "silently wrong result or ignored input"
    return "other"


#: the table's history (rows run on an earlier code), kept when it is written again
NOTES = [
    "Rows 1-93 are the command line's earlier table (its fast cases run in "
    "tests/test_bad_inputs.py). Rows 94-188 (the API, sweeps, converge, "
    "restarts, mesh files, signals of state and MPI) were also run on the code before the "
    "validation layer, the collective outcome, the sweep folder rules and the run fingerprint "
    "(`python benchmarks/faults/bad_inputs.py --start 93 --timeout 60` in a checkout of that "
    "code): 41 clean, 6 hang, 17 traceback or crash, 26 silently wrong result or ignored input, "
    "5 other (a refusal after files were written, a solver failure instead of a refusal, "
    "`T=np.int64(1)` refused); now 95 clean. Row \"2 ranks: a damage law raising on rank 1 at "
    "set-up\" raises on the law's second call, which only the validation layer's symbolic check "
    "makes: on the earlier code it ran (ok) without raising.", "",
    "Rows 189-314 (benchmarks/faults/bad_inputs_more.py) are other cases of every class: a "
    "user's function raising on one rank only (on_step mid-run, zeta0(x), a law in a sweep "
    "point, a load in a study), the sweep folder's rules, restarts that change one thing that "
    "defines the run (a zeta0(x) changed inside its range, a load's fem.Constant, an "
    "Expression-like load object, a law's literal, PETSc options, a mesh file of the same name "
    "with a node moved), summaries and study tables cut short, every argument of every entry "
    "point (types, NumPy scalars, NaN/inf, empty lists, callables of the wrong kind), absurd "
    "step counts, mesh files, signals, non-finite sources on 2.3, 3.1, 3.2 and 3.3. Run on the "
    "code before they were added (`python benchmarks/faults/bad_inputs.py --start 188 "
    "--timeout 60` in a checkout of that code): 111 clean, 6 traceback or crash (sweep(out="
    "None), params E=inf, run(on_step=5), run(comm=...), steps(out=None), read_mesh(comm=...)), "
    "6 silently wrong result or ignored input (a restart with zeta0(x) changed inside its "
    "range, with other PETSc options, a sweep rerun with another traction, a study's table cut "
    "short left so, converge(progress='no'), sweep --plot of an unknown scalar), 3 other (a "
    "valid restart refused: a tag [2] for 2; a refusal after files were written: a mesh file "
    "with a node moved; a user's on_step raising left the summary without the error), 0 hang, "
    "0 user file lost; now 126 clean (sweep --plot of an unknown scalar was the last one open: "
    "it warned after the runs, the final scalars being known only once a model was built; they "
    "are now known from the model class and the problem before any work, and the plot is "
    "refused there).", "",
    "Rows 315-320 are the two mechanisms added last: a sweep's plot checked against the final "
    "scalars before any run (an unknown one refused, a contact scalar of a problem with a "
    "contact part accepted), and `with dd.steps(...) as run:`, whose exit sees an exception of "
    "the loop body (failed, with the error; on 2 ranks a raise on rank 1 alone ends both ranks "
    "with one line), a break being a stop; a plain `for step in dd.steps(...)` loop raising on "
    "rank 1 alone ends both ranks too (the ranks agree after every step whether their loops "
    "went on; on the code before, it had not ended after 40 s).", "",
    "Every row below is the result of the current code: the table is written again whole, in "
    "chunks (`python benchmarks/faults/bad_inputs.py --start 0 --stop 100`, then `--start 100 "
    "--stop 200`, then `--start 200`; each chunk merged into the table as last recorded).", "",
]


def write_tables(results, out: Path):
    out.mkdir(parents=True, exist_ok=True)
    (out / "bad_inputs.json").write_text(json.dumps(results, indent=1, allow_nan=False) + "\n")
    counts = {}
    for r in results:
        counts[r["outcome"]] = counts.get(r["outcome"], 0) + 1
    passed = sum(r["pass"] for r in results)
    kinds = {}
    for r in results:
        kinds[kind(r)] = kinds.get(kind(r), 0) + 1
    lines = ["# Bad input: what the command line and the API do with it", "",
             f"{len(results)} cases, {passed} with the expected outcome. Outcomes: "
             + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())) + ". By class of "
             "defect: " + ", ".join(f"{k} {v}" for k, v in sorted(kinds.items())) + ".", "",
             "Cases marked (API) run a user's script (the API's exceptions mapped to the command "
             "line's exit statuses by a small harness: InputError 2, a solver failure 3, an "
             "output error 4; any other exception is a traceback); cases under mpirun end as a "
             f"hang when still running after {MPI_TIMEOUT} s.", "",
             "Written by `python benchmarks/faults/bad_inputs.py`; each case runs in a folder "
             "of its own (`o` is the output folder). *refused*: exit status 2, one line, no "
             "file written or changed; *failed*: exit status 3, one line, summary.json "
             "`failed` with the error; *warned*: exit status 0 with one warning line; *ok*: "
             "exit status 0 (a case that must work). Files before -> after count every file "
             "of the case's folder.", "", *NOTES,
             "| # | class | case | exit | outcome (expected) | files before -> after | message |",
             "|---|---|---|---|---|---|---|"]
    for i, r in enumerate(results, 1):
        mark = "" if r["pass"] else " **UNEXPECTED**"
        message = r["message"].replace("|", "\\|")
        lines.append(f"| {i} | {r['class']} | {r['id']} | {r['exit_status']} | "
                     f"{r['outcome']} ({r['expected']}){mark} | {len(r['files_before'])} -> "
                     f"{len(r['files_after'])} | {message} |")
    (out / "bad_inputs.md").write_text("\n".join(lines) + "\n")
    return counts, passed


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="+", help="case ids (substrings)")
    parser.add_argument("--out", default=str(HERE), help="folder of the two tables")
    parser.add_argument("--timeout", type=float, default=300.0, help="seconds per case")
    parser.add_argument("--start", type=int, default=0,
                        help="skip the first START cases (e.g. 93: only the API, sweep, "
                             "converge, restart and MPI cases)")
    parser.add_argument("--stop", type=int, default=None,
                        help="run the cases up to row STOP (with --start: a chunk of rows, "
                             "merged into the table as last recorded)")
    args = parser.parse_args()
    TIMEOUT[0] = args.timeout
    cases = [c for c in CASES[args.start:args.stop]
             if not args.only or any(s in c["id"] for s in args.only)]
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        bases = make_bases(root, lambda a, cwd: _check(_subprocess(a, cwd)))
        results = []
        for case in cases:
            r = run_case(case, bases, root)
            print(f"{r['outcome']:>10s} ({r['expected']}) exit {r['exit_status']} "
                  f"{r['id']}: {r['message'][:110]}", flush=True)
            results.append(r)
    if args.start or args.stop is not None or args.only:  # the other rows as last recorded
        results = merged(results, Path(args.out) / "bad_inputs.json")
    counts, passed = write_tables(results, Path(args.out))
    kinds = {}
    for r in results:
        kinds[kind(r)] = kinds.get(kind(r), 0) + 1
    print(f"{len(results)} cases, {passed} as expected: {counts}; by class: {kinds}")


def merged(results, earlier: Path) -> list:
    """``results`` in place of the rows of the same id in the table ``earlier``, in the order of
    CASES (rows of neither are dropped)."""
    try:
        rows = {r["id"]: r for r in json.loads(earlier.read_text())}
    except (OSError, ValueError):
        rows = {}
    rows.update((r["id"], r) for r in results)
    return [rows[c["id"]] for c in CASES if c["id"] in rows]


def _check(result):
    status, out, err = result
    if status != 0:
        raise SystemExit(f"a base run failed ({status}): {err}")


if __name__ == "__main__":
    main()
