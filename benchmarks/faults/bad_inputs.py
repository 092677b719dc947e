"""Bad input, tried as a careless user would: every case runs the real command line and records
its exit status, its message (the first line of stderr), the files of its folder before and
after, and the outcome. Writes bad_inputs.json and bad_inputs.md beside this script.

    python benchmarks/faults/bad_inputs.py [--only ID ...] [--out DIR]

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
#: a folder name (in the case's own working folder)
OUT = "o"


# ---------------------------------------------------------------------------- fixtures
def _strict(text):
    def refuse(name):
        raise ValueError(f"bare {name} is not JSON")
    return json.loads(text, parse_constant=refuse)


def user_files(folder, names):
    """Files the user made (recorded as such: they must stay byte for byte)."""
    folder.mkdir(parents=True, exist_ok=True)
    for name in names:
        (folder / name).write_bytes(f"the user's own {name}\n".encode())
    return [str(Path(folder.name) / n) for n in names]


def gmsh_mesh(path, kind):
    """A .msh file: 'ok' (unit square, cells tag 10, left edge 1, the others 2), 'notags'
    (no physical groups), 'tag1' (only the left edge tagged), '1d' (a line), '3d' (a cube)."""
    from damage_dolfinx.runtime.runfolder import _gmsh
    gmsh = _gmsh()  # the package's gmsh session (the tests run in one process)
    gmsh.model.add("m")
    occ = gmsh.model.occ
    if kind == "1d":
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
    def none(work, bases):
        return []

    def copy(kind):
        def setup(work, bases):
            shutil.copytree(bases[kind], work / OUT)
            return []
        return setup

    def run_plus_user(names):
        def setup(work, bases):
            shutil.copytree(bases["run"], work / OUT)
            return user_files(work / OUT, names)
        return setup

    def study_plus_user(names):
        def setup(work, bases):
            shutil.copytree(bases["study"], work / OUT)
            return user_files(work / OUT, names)
        return setup

    def only_user(names):
        return lambda work, bases: user_files(work / OUT, names)

    def checkpoint_edit(change):
        def setup(work, bases):
            shutil.copytree(bases["run"], work / OUT)
            edit_checkpoint(work / OUT / "checkpoint.npz", change)
            return []
        return setup

    def summary_text(text):
        def setup(work, bases):
            shutil.copytree(bases["run"], work / OUT)
            (work / OUT / "summary.json").write_text(text)
            return []
        return setup

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
        def setup(work, bases):
            (work / name).write_bytes(content)
            return [name]
        return setup

    def manifest_text(text):
        def setup(work, bases):
            shutil.copytree(bases["run"], work / OUT)
            (work / OUT / "manifest.json").write_text(text)
            return []
        return setup

    def out_is_file(work, bases):
        (work / OUT).write_text("the user's file\n")
        return [OUT]

    tiny = ["--n", "5", "--k", "0.25", "--no-figures", "--quiet"]
    run = ["run", "2.1-ex1", *tiny]
    conv = ["converge", "2.1-ex1", "--ref-n", "10", "--ref-k", "0.125", "--quiet"]
    c = []

    def case(id_, cls, args, setup=none, expect="refused", fast=True):
        c.append(dict(id=id_, cls=cls, args=args, setup=setup, expect=expect, fast=fast))

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
    return c


CASES = _cases()


# ---------------------------------------------------------------------------- running
def make_bases(root: Path, runner) -> dict:
    """The earlier run (2.1-ex1 and 2.4-ex1) and study the folder cases start from."""
    bases = {"run": root / "base_run", "run24": root / "base_run24", "study": root / "base_study"}
    runner([*RUN, "--out", str(bases["run"])], root)
    runner(["run", "2.4-ex1", "--n", "4", "--k", "0.25", "--T", "0.5", "--no-figures",
            "--quiet", "--out", str(bases["run24"])], root)
    runner([*STUDY, "--out", str(bases["study"])], root)
    return bases


#: seconds a case may take (a case still running then counts as "no end")
TIMEOUT = [300]


def _subprocess(args, cwd):
    try:
        proc = subprocess.run([sys.executable, "-m", "damage_dolfinx.cli", *args], cwd=cwd,
                              env=ENV, capture_output=True, text=True, timeout=TIMEOUT[0])
    except subprocess.TimeoutExpired as exc:
        err = exc.stderr.decode(errors="replace") if isinstance(exc.stderr, bytes) else \
            (exc.stderr or "")
        return None, "", err
    return proc.returncode, proc.stdout, proc.stderr


def snapshot(work: Path) -> dict:
    """name (relative to the case's folder) -> sha256 of every file."""
    out = {}
    for path in sorted(work.rglob("*")):
        if path.is_file():
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
    elif "Traceback" in stderr:
        outcome = "traceback"
    elif touched:
        outcome = "user file touched"
    elif bad_json:
        outcome = "invalid JSON"
    elif status == 2 and len(ours) == 1 and not changed:
        outcome = "refused"
    elif status == 3 and len(ours) == 1 and summary.get("status") == "failed" and \
            summary.get("error"):
        outcome = "failed"
    elif status == 0 and any("warning" in line.lower() for line in ours):
        outcome = "warned"
    elif status == 0:
        outcome = "ok"
    else:
        outcome = f"other (exit {status}, {len(ours)} line(s), {len(changed)} file(s) changed)"
    message = ours[0] if ours else (lines[0] if lines else "")
    return {"id": case["id"], "class": case["cls"],
            "command": "damage-dolfinx " + " ".join(case["args"]), "exit_status": status,
            "message": message, "files_before": sorted(before), "files_after": sorted(after),
            "user_files_touched": touched, "invalid_json": bad_json, "outcome": outcome,
            "expected": case["expect"], "pass": outcome == case["expect"]}


def run_case(case, bases, root: Path, runner=_subprocess) -> dict:
    work = Path(tempfile.mkdtemp(dir=root))
    user = case["setup"](work, bases)
    before = snapshot(work)
    start = time.perf_counter()
    status, _, stderr = runner(case["args"], work)
    result = classify(case, status, stderr, before, snapshot(work), user, work)
    result["seconds"] = round(time.perf_counter() - start, 1)
    shutil.rmtree(work, ignore_errors=True)
    return result


def write_tables(results, out: Path):
    out.mkdir(parents=True, exist_ok=True)
    (out / "bad_inputs.json").write_text(json.dumps(results, indent=1, allow_nan=False) + "\n")
    counts = {}
    for r in results:
        counts[r["outcome"]] = counts.get(r["outcome"], 0) + 1
    passed = sum(r["pass"] for r in results)
    lines = ["# Bad input: what the command line does with it", "",
             f"{len(results)} cases, {passed} with the expected outcome. Outcomes: "
             + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())) + ".", "",
             "Written by `python benchmarks/faults/bad_inputs.py`; each case runs in a folder "
             "of its own (`o` is the output folder). *refused*: exit status 2, one line, no "
             "file written or changed; *failed*: exit status 3, one line, summary.json "
             "`failed` with the error; *warned*: exit status 0 with one warning line; *ok*: "
             "exit status 0 (a case that must work). Files before -> after count every file "
             "of the case's folder.", "",
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
    args = parser.parse_args()
    TIMEOUT[0] = args.timeout
    cases = [c for c in CASES if not args.only or any(s in c["id"] for s in args.only)]
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        bases = make_bases(root, lambda a, cwd: _check(_subprocess(a, cwd)))
        results = []
        for case in cases:
            r = run_case(case, bases, root)
            print(f"{r['outcome']:>10s} ({r['expected']}) exit {r['exit_status']} "
                  f"{r['id']}: {r['message'][:110]}", flush=True)
            results.append(r)
    counts, passed = write_tables(results, Path(args.out))
    print(f"{len(results)} cases, {passed} as expected: {counts}")


def _check(result):
    status, out, err = result
    if status != 0:
        raise SystemExit(f"a base run failed ({status}): {err}")


if __name__ == "__main__":
    main()
