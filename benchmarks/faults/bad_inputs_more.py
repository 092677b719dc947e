"""The held-out cases of the bad-input table (rows after the API/sweep/converge/restart/MPI
probe): other cases of each class, tried as a careful user would. Called from
bad_inputs._api_cases with its helpers (``ns``: that module's names)."""
import shutil
import subprocess
import sys


#: the representative cases that also run in tests/test_bad_inputs.py (one or two of each
#: mechanism: the rule per argument name, the Problem's data, the fingerprint, the summaries
#: and outputs rebuilt from disk, the sweep folder)
FAST = {"run(on_step=5)", "run(comm='world')", "steps(out=None)", "converge(progress='no')",
        "sweep(out=None)", "read_mesh(comm='world')", "from_gmsh(model=42)", "params E=inf",
        "zeta0(x) NaN at one node", "restart, zeta0(x) changed inside, same min and max",
        "--restart -mech_ksp_rtol 1e-2 (a result-changing PETSc option)",
        "restart, a traction tag given as [2] (the same run)",
        "sweep restart, the traction changed", "summary.json binary garbage, --restart",
        "study's errors.csv cut short, converge --restart",
        "sweep again, a user's file in point_0/mine/",
        "on_step raising at step 1 (serial): the summary says failed"}


def more_cases(case_, api_, ns, none, copy, only_user, mesh, run, conv, sweep_base):
    OUT = ns["OUT"]

    def case(id_, *args, fast=None, **kw):
        case_(id_, *args, fast=id_ in FAST, **kw)

    def api(id_, *args, fast=None, **kw):
        api_(id_, *args, fast=id_ in FAST, **kw)

    prepared, summary_check = ns["prepared"], ns["summary_check"]

    def text_file(name, content):
        return prepared(write={name: content})

    def run_edit(edit, kind="run"):
        """A copy of the base ``kind`` with ``edit(folder)`` applied."""
        return prepared(kind, edit=edit)

    # ------------------------------------------------------------ 1. one rank fails, all end
    raise_on = ("def boom(step):\n    if MPI.COMM_WORLD.rank == {r} and step.n == {n}:\n"
                "        raise RuntimeError('rank {r} gives up')\n")
    api("on_step raising at step 1 (serial): the summary says failed", "mpi",
        raise_on.format(r=0, n=1) + "try:\n    run(problem(T=0.04), on_step=boom)\n"
        "except RuntimeError as exc:\n    import gc, json\n    gc.collect()\n"
        "    s = json.load(open('o/summary.json'))\n"
        "    print(f'damage-dolfinx: failed: {exc} (summary: {s[\"status\"]})', "
        "file=sys.stderr)\n    sys.exit(3 if s['status'] == 'failed' else 1)",
        expect="failed")
    api("2 ranks: on_step raising on rank 1 mid-run", "mpi",
        raise_on.format(r=1, n=1) + "run(problem(T=0.04), on_step=boom)", expect="failed",
        fast=False, ranks=2)
    api("3 ranks: on_step raising on rank 2 at the first step", "mpi",
        raise_on.format(r=2, n=0) + "run(problem(T=0.04), on_step=boom)", expect="failed",
        fast=False, ranks=3)
    api("2 ranks: zeta0(x) raising on rank 1 only", "mpi",
        "def z0(x):\n    if MPI.COMM_WORLD.rank == 1:\n        raise ValueError('no')\n"
        "    return 0.5 + 0 * x[0]\nrun(problem(zeta0=z0))", fast=False, ranks=2)
    api("2 ranks: a damage law raising on rank 1 during sweep point 2", "mpi",
        "calls = []\ndef law(e, z, p):\n    calls.append(1)\n"
        "    if MPI.COMM_WORLD.rank == 1 and p.kappa > 1.5:\n"
        "        raise ZeroDivisionError('r1')\n    return -z\n"
        "s = dd.sweep(problem(damage_law=dd.DamageLaw(law, 'own')), 'o', {'kappa': [1.0, 2.0]}, "
        "figures=False, progress=False)\n"
        "if s['status'] == 'failed' and MPI.COMM_WORLD.rank == 0:  # the API returns it\n"
        "    print(f'damage-dolfinx: failed: points {s[\"failed\"]}', file=sys.stderr)\n"
        "sys.exit(3 if s['status'] == 'failed' else 0)", expect="failed", fast=False, ranks=2)
    api("2 ranks: a load raising on rank 1 at converge's second level (set-up)", "mpi",
        "calls = []\ndef load(x, t):\n    calls.append(1)\n"
        "    if MPI.COMM_WORLD.rank == 1 and len(calls) > 2:\n        raise RuntimeError('r1')\n"
        "    return ufl.as_vector((10 * t, 0.0))\n"
        "dd.converge(problem(traction=load), 'o', n=[2], k=[0.01], ref_n=4, ref_k=0.005, "
        "progress=False)", fast=False, ranks=2)

    # ------------------------------------------------------------ 2. sweep folder discipline
    def no_point_1(folder):
        shutil.rmtree(folder / "point_1")

    user_in_point_subfolder = prepared("sweep", user=["notes.txt"], where=f"{OUT}/point_0/mine")
    point_is_users_file = prepared("sweep", edit=no_point_1,
                                   write={f"{OUT}/point_1": b"the user's own file\n"})
    user_beside_sweep = prepared("sweep", user=["notes.txt"])

    case("sweep again, a user's file in point_0/mine/", "sweep",
         [*sweep_base, "--set", "kappa=1,2", "--out", OUT], user_in_point_subfolder)
    case("sweep again, point_1 is a file of the user's", "sweep",
         [*sweep_base, "--set", "kappa=1,2", "--out", OUT], point_is_users_file)
    case("sweep again, a user's notes beside the finished sweep", "sweep",
         [*sweep_base, "--set", "kappa=1,2", "--out", OUT], user_beside_sweep)
    case("sweep again with another grid", "sweep",
         [*sweep_base, "--set", "kappa=1,3", "--out", OUT], copy("sweep"))
    case("sweep again with another n", "sweep",
         ["sweep", "2.1-ex1", "--n", "10", "--k", "0.25", "--no-figures", "--quiet", "--set",
          "kappa=1,2", "--out", OUT], copy("sweep"))
    case("sweep again with another example", "sweep",
         ["sweep", "2.4-ex1", "--n", "4", "--k", "0.25", "--T", "0.5", "--no-figures",
          "--quiet", "--set", "kappa=1,2", "--out", OUT], copy("sweep"))
    case("sweep, the user's own sweep.csv in an empty folder", "sweep",
         [*sweep_base, "--set", "kappa=1,2", "--out", OUT], only_user(["sweep.csv"]))
    case("sweep, manifest.json damaged", "sweep",
         [*sweep_base, "--set", "kappa=1,2", "--out", OUT],
         run_edit(lambda f: (f / "manifest.json").write_text("{oops"), "sweep"))
    case("sweep again, a point's summary.json cut short", "sweep",
         [*sweep_base, "--set", "kappa=1,2", "--out", OUT],
         run_edit(lambda f: (f / "point_1" / "summary.json").write_text('{"sta'), "sweep"),
         "ok", fast=False, verify=summary_check(points=2))
    case("sweep again, sweep.csv deleted", "sweep",
         [*sweep_base, "--set", "kappa=1,2", "--out", OUT],
         run_edit(lambda f: (f / "sweep.csv").unlink(), "sweep"), "ok", fast=False,
         verify=lambda w: None if (w / OUT / "sweep.csv").is_file() else "sweep.csv not rebuilt")
    case("sweep --point 7 of 2 points", "sweep",
         [*sweep_base, "--set", "kappa=1,2", "--point", "7", "--out", OUT])
    case("sweep --ranks-per-point 0", "sweep",
         [*sweep_base, "--set", "kappa=1,2", "--ranks-per-point", "0", "--out", OUT])
    case("sweep --plot of an unknown scalar", "sweep",
         [*sweep_base, "--set", "kappa=1,2", "--plot", "bogus", "--out", OUT])
    case("sweep --set kappa= (no value)", "sweep", [*sweep_base, "--set", "kappa=", "--out", OUT])
    case("sweep --set kappa=1,1 (twice)", "sweep",
         [*sweep_base, "--set", "kappa=1,1", "--out", OUT])
    case("sweep --k 1e-12", "sweep",
         ["sweep", "2.1-ex1", "--n", "5", "--k", "1e-12", "--set", "kappa=1,2", "--out", OUT])
    api("sweep grid {}", "api", "dd.sweep(problem(), 'o', {})")
    api("sweep grid {'kappa': 2.0} (one value, as --set kappa=2)", "api",
        "dd.sweep(problem(), 'o', {'kappa': 2.0}, figures=False, progress=False)", expect="ok",
        fast=False)
    api("sweep grid {'kappa': []}", "api", "dd.sweep(problem(), 'o', {'kappa': []})")
    api("sweep grid with a non-text key", "api", "dd.sweep(problem(), 'o', {3: [1.0]})")
    api("sweep grid {'E': ['soft']}", "api", "dd.sweep(problem(), 'o', {'E': ['soft']})")
    api("sweep grid {'E': [inf]}", "api", "dd.sweep(problem(), 'o', {'E': [float('inf')]})")
    api("sweep(n=0)", "api", "dd.sweep(problem(), 'o', {'kappa': [1.0]}, n=0)")
    api("sweep(plot=3)", "api", "dd.sweep(problem(), 'o', {'kappa': [1.0]}, plot=3)")
    api("sweep(point=-1)", "api", "dd.sweep(problem(), 'o', {'kappa': [1.0]}, point=-1)")
    api("sweep(out=None)", "api", "dd.sweep(problem(), None, {'kappa': [1.0]})")

    # ------------------------------------------------------------ 3. restart fingerprint
    first = "run(problem(T=0.02), checkpoint_every=1)\n"
    api("restart, zeta0(x) changed inside, same min and max", "restart",
        first="run(problem(T=0.02, zeta0=lambda x: 0.5 + 0.5 * (x[0] > 1.0)), "
              "checkpoint_every=1)\n",
        code="run(problem(T=0.04, zeta0=lambda x: 0.5 + 0.5 * (x[0] > 1.5)), restart=True)",
        fast=False)
    api("restart, a load's fem.Constant amplitude changed", "restart",
        first="from dolfinx import fem\nA = [1.0]\n"
              "def load(x, t):\n    return ufl.as_vector((fem.Constant(x.ufl_domain(), "
              "A[0]) * t, 0.0))\nrun(problem(T=0.02, traction=load), checkpoint_every=1)\n",
        code="from dolfinx import fem\nA = [50.0]\n"
             "def load(x, t):\n    return ufl.as_vector((fem.Constant(x.ufl_domain(), "
             "A[0]) * t, 0.0))\nrun(problem(T=0.04, traction=load), restart=True)", fast=False)
    expr = ("class Load:\n    def __init__(self, a):\n        self.a = a\n"
            "    def __call__(self, x, t):\n        return ufl.as_vector((self.a * t, 0.0))\n")
    api("restart, an Expression-like load object's attribute changed", "restart",
        first=expr + "run(problem(T=0.02, traction=Load(10.0)), checkpoint_every=1)\n",
        code=expr + "run(problem(T=0.04, traction=Load(30.0)), restart=True)", fast=False)
    api("restart, a law's literal changed", "restart",
        first="run(problem(T=0.02, damage_law=dd.DamageLaw(lambda e, z, p: -0.1 * z, 'own')), "
              "checkpoint_every=1)\n",
        code="run(problem(T=0.04, damage_law=dd.DamageLaw(lambda e, z, p: -0.2 * z, 'own')), "
             "restart=True)", fast=False)
    api("restart, params kappa changed", "restart", first=first,
        code="run(problem(T=0.04, params={'kappa': 7.0}), restart=True)", fast=False)
    api("restart, another k", "restart", first=first,
        code="run(problem(T=0.04, k=0.005), restart=True)", fast=False)
    api("restart, a traction tag given as [2] (the same run)", "restart", first=first,
        code="s = run(problem(T=0.04, boundaries={'clamped': 1, 'traction': [2], "
             "'bilateral': 3}), restart=True)\nassert s['steps_done'] == 4, s",
        expect="ok", fast=False)
    api("sweep restart, the traction changed", "restart",
        first="dd.sweep(problem(), 'o', {'kappa': [1.0, 2.0]}, figures=False, progress=False)\n",
        code="dd.sweep(problem(traction=lambda x, t: ufl.as_vector((99.0 * t, 0.0))), 'o', "
             "{'kappa': [1.0, 2.0]}, figures=False, progress=False, restart=True)", fast=False)
    api("converge restart, the traction changed", "restart",
        first="dd.converge(problem(), 'o', n=[2], k=[0.01], ref_n=4, ref_k=0.005, "
              "progress=False)\n",
        code="dd.converge(problem(traction=lambda x, t: ufl.as_vector((99.0 * t, 0.0))), 'o', "
             "n=[2], k=[0.01], ref_n=4, ref_k=0.005, progress=False, restart=True)", fast=False)

    case("--restart -mech_ksp_rtol 1e-2 (a result-changing PETSc option)", "restart",
         [*run, "--T", "2", "--restart", "--out", OUT, "-mech_ksp_type", "cg",
          "-mech_pc_type", "jacobi", "-mech_ksp_rtol", "1e-2"], copy("run"))

    def moved_mesh_run(work, bases):
        ns["gmsh_mesh"](work / "m.msh", "ok")
        status = subprocess.run(
            [sys.executable, "-m", "damage_dolfinx.cli", "run", "2.1-ex2a", "--mesh", "m.msh",
             "--k", "0.25", "--T", "0.5", "--no-figures", "--quiet", "--out", OUT],
            cwd=work, env=ns["ENV"], capture_output=True, text=True)
        if status.returncode != 0:
            raise RuntimeError(f"the earlier run failed: {status.stderr}")
        lines = (work / "m.msh").read_text().splitlines()
        inside = False
        for i, line in enumerate(lines):
            inside = (inside or line == "$Nodes") and line != "$EndNodes"
            parts = line.split()
            if inside and len(parts) == 3 and all("." in p or "e" in p for p in parts[:2]):
                x, y = float(parts[0]), float(parts[1])
                if 0.1 < x < 0.9 and 0.1 < y < 0.9:
                    lines[i] = f"{x + 0.02!r} {y} {parts[2]}"
                    break
        (work / "m.msh").write_text("\n".join(lines) + "\n")
        return ["m.msh"]
    case("--restart on a mesh file of the same name, a node moved", "restart",
         ["run", "2.1-ex2a", "--mesh", "m.msh", "--k", "0.25", "--T", "1", "--no-figures",
          "--quiet", "--restart", "--out", OUT], moved_mesh_run, fast=False)

    # ------------------------------------------------------------ 4. summaries rebuilt
    case("summary.json binary garbage, --restart", "restart", [*run, "--restart", "--out", OUT],
         run_edit(lambda f: (f / "summary.json").write_bytes(b"\x00\xff\x13garbage")), "ok",
         verify=summary_check("completed", 4))
    case("summary.json a JSON list, --restart", "restart", [*run, "--restart", "--out", OUT],
         run_edit(lambda f: (f / "summary.json").write_text("[]")), "ok",
         verify=summary_check("completed", 4))
    case("summary.json left 'running' (killed), --restart", "restart",
         [*run, "--restart", "--out", OUT],
         run_edit(lambda f: (f / "summary.json").write_text(
             '{"schema": "damage-dolfinx/summary/v1", "status": "running", "steps_done": 1}')),
         "ok", verify=summary_check("completed", 4))
    case("history.csv cut mid-line, --restart --T 2", "restart",
         [*run, "--T", "2", "--restart", "--out", OUT],
         run_edit(lambda f: (f / "history.csv").write_text(
             (f / "history.csv").read_text()[:-7])), "ok",
         verify=summary_check("completed", 8))
    case("summary.json deleted, --restart", "restart", [*run, "--restart", "--out", OUT],
         run_edit(lambda f: (f / "summary.json").unlink()), "ok",
         verify=summary_check("completed", 4))
    def table_whole(name):
        def verify(work):
            lines = (work / OUT / name).read_text().splitlines()
            if len(lines) < 2 or len({line.count(",") for line in lines}) != 1:
                return f"{name} left cut short ({len(lines)} line(s))"
            return None
        return verify
    case("study's errors.csv cut short, converge --restart", "restart",
         [*conv, "--n", "5", "--k", "0.25", "0.5", "--restart", "--out", OUT],
         run_edit(lambda f: (f / "errors.csv").write_text(
             (f / "errors.csv").read_text()[:150]), "study"), "ok", fast=False,
         verify=table_whole("errors.csv"))
    case("study's summary.json cut short, converge --restart", "restart",
         [*conv, "--n", "5", "--k", "0.25", "0.5", "--restart", "--out", OUT],
         run_edit(lambda f: (f / "summary.json").write_text('{"sche'), "study"), "ok",
         fast=False, verify=summary_check("completed"))

    # ------------------------------------------------------------ 5. the API's bad input
    api("T=True (a flag)", "api", "run(problem(T=True))")
    api("T=inf", "api", "run(problem(T=float('inf')))")
    api("T=np.float32(nan)", "api", "run(problem(T=np.float32('nan')))")
    api("k='0.01' (text)", "api", "run(problem(k='0.01'))")
    api("k=np.int64(0)", "api", "run(problem(k=np.int64(0)))")
    api("T not a multiple of k", "api", "run(problem(T=0.025, k=0.01))")
    api("k=1e-12 (2e10 steps)", "api", "run(problem(T=0.02, k=1e-12))")
    api("n=True", "api", "run(problem(n=True))")
    api("zeta0=nan", "api", "run(problem(zeta0=float('nan')))")
    api("zeta0=0", "api", "run(problem(zeta0=0))")
    api("zeta0(x) NaN at one node", "api",
        "run(problem(zeta0=lambda x: np.where(x[0] > 1.9, np.nan, 0.5)))")
    api("zeta0 a function without argument", "api", "run(problem(zeta0=lambda: 0.5))")
    api("zeta0(x) returning one number", "api", "run(problem(zeta0=lambda x: 0.5))")
    api("boundaries {}", "api", "run(problem(boundaries={}))")
    api("boundaries {'clamped': -1}", "api", "run(problem(boundaries={'clamped': -1, "
        "'traction': 2}))")
    api("boundaries {'clamped': 1.5}", "api", "run(problem(boundaries={'clamped': 1.5, "
        "'traction': 2}))")
    api("boundaries a list of pairs", "api",
        "run(problem(boundaries=[('clamped', 1), ('traction', 2)]))")
    api("one tag in two roles", "api",
        "run(problem(boundaries={'clamped': 1, 'traction': [1, 2]}))")
    api("body force returning a matrix", "api",
        "run(problem(body_force=lambda x, t: ufl.Identity(2)))")
    api("traction(x) with one argument", "api",
        "run(problem(traction=lambda x: ufl.as_vector((1.0, 0.0))))")
    api("traction returning a NumPy array", "api",
        "run(problem(traction=lambda x, t: np.array([1.0, 0.0])))")
    api("DamageLaw('fast') (not a function)", "api",
        "run(problem(damage_law=dd.DamageLaw('fast', 'own')))")
    api("params E=inf", "api", "run(problem(params={'E': float('inf')}))")
    api("params kappa=-inf", "api", "run(problem(params={'kappa': -float('inf')}))")
    api("params a non-text key", "api", "run(problem(params={1: 2.0}))")
    api("params E a 0-d array", "api", "run(problem(params={'E': np.array([[2e4]])}))")
    api("model ' 2.1' (a space)", "api", "run(problem(model=' 2.1'))")
    api("mesh a 1-tuple", "api", "run(problem(mesh=(1,), n=None))")
    api("mesh family returning 42", "api", "run(problem(mesh=lambda comm, n: 42))")
    api("mesh family raising", "api",
        "def fam(comm, n):\n    raise ValueError('no such level')\nrun(problem(mesh=fam))")
    api("mesh file of binary garbage", "api", "run(problem(mesh='m.msh', n=None))",
        setup=text_file("m.msh", bytes(range(256)) * 8))
    api("mesh file without physical groups", "api",
        "run(problem(mesh='m.msh', n=None, boundaries={'clamped': 1, 'traction': 2}))",
        setup=mesh("notags"))
    api("a 3-D mesh file for a 2.2 problem", "api",
        "run(problem(model='2.2', mesh='m.msh', n=None, boundaries={'clamped': 1, "
        "'traction': 2, 'tresca': 2}))", setup=mesh("3d"))
    api("run(out='')", "api", "run(problem(), out='')")
    api("run(out=42)", "api", "run(problem(), out=42)")
    api("run(progress='no')", "api", "run(problem(), progress='no')")
    api("run(on_step=5)", "api", "run(problem(), on_step=5)")
    api("run(comm='world')", "api", "run(problem(), comm='world')")
    api("run(T=1e-300) (zero steps)", "api", "run(problem(), T=1e-300)")
    api("run of a catalogue id, k above T", "api",
        "dd.run('2.1-ex1', 'o', n=5, k=0.5, T=0.25, figures=False, progress=False)")
    api("steps(restart='yes')", "api", "next(iter(dd.steps(problem(), 'o', restart='yes')))")
    api("steps(n=0)", "api", "next(iter(dd.steps(problem(), 'o', n=0)))")
    api("steps(out=None)", "api", "next(iter(dd.steps(problem(), None)))")
    api("converge(k=[])", "api",
        "dd.converge(problem(), 'o', n=[2], k=[], ref_n=4, ref_k=0.005)")
    api("converge(ref_k=0)", "api",
        "dd.converge(problem(), 'o', n=[2], k=[0.01], ref_n=4, ref_k=0)")
    api("converge(k=[nan])", "api",
        "dd.converge(problem(), 'o', n=[2], k=[float('nan')], ref_n=4, ref_k=0.005)")
    api("converge(n=[2.0])", "api",
        "dd.converge(problem(), 'o', n=[2.0], k=[0.01], ref_n=4, ref_k=0.005)")
    api("converge(progress='no')", "api",
        "dd.converge(problem(), 'o', n=[2], k=[0.01], ref_n=4, ref_k=0.005, progress='no')")
    api("converge(T='1')", "api",
        "dd.converge(problem(), 'o', n=[2], k=[0.01], ref_n=4, ref_k=0.005, T='1')")
    api("converge(k not a multiple of ref_k)", "api",
        "dd.converge(problem(), 'o', n=[2], k=[0.0075], ref_n=4, ref_k=0.005)")
    api("read_mesh(dim=2.5)", "api", "dd.read_mesh('m.msh', dim=2.5)", setup=mesh("ok"))
    api("read_mesh of a text file named .txt", "api", "dd.read_mesh('m.txt')",
        setup=text_file("m.txt", b"not a mesh\n"))
    api("read_mesh of binary garbage", "api", "dd.read_mesh('m.msh')",
        setup=text_file("m.msh", bytes(range(256)) * 8))
    api("read_mesh of an empty file", "api", "dd.read_mesh('m.msh')",
        setup=text_file("m.msh", b""))
    api("read_mesh of a 3-D file with dim=2", "api", "dd.read_mesh('m.msh', dim=2)",
        setup=mesh("3d"))
    api("read_mesh(comm='world')", "api", "dd.read_mesh('m.msh', comm='world')",
        setup=mesh("ok"))
    api("from_gmsh(model=42)", "api", "dd.from_gmsh(model=42)")
    api("model_defaults('9.9')", "api", "dd.model_defaults('9.9')")
    api("model_defaults(2.1) (a float)", "api", "dd.model_defaults(2.1)")
    api("model_defaults(None)", "api", "dd.model_defaults(None)")

    # ------------------------------------------------------------ 6. zero/absurd step counts
    case("--T 0.3 not a multiple of --k 0.25", "ranges",
         ["run", "2.1-ex1", "--n", "5", "--k", "0.25", "--T", "0.3", "--out", OUT])
    case("--T 1e300", "ranges", ["run", "2.1-ex1", "--n", "5", "--T", "1e300", "--out", OUT])
    case("converge --k not a multiple of --ref-k", "ranges",
         [*conv, "--n", "5", "--k", "0.3", "--out", OUT])

    # ------------------------------------------------------------ 7. mesh files
    case("--mesh binary garbage", "mesh", ["run", "2.1-ex2a", "--mesh", "m.msh", "--out", OUT],
         text_file("m.msh", bytes(range(256)) * 8))
    case("--mesh a .txt file", "mesh", ["run", "2.1-ex2a", "--mesh", "m.txt", "--out", OUT],
         text_file("m.txt", b"not a mesh\n"))

    dangling_mesh = prepared(links={"m.msh": "nowhere.msh"})
    case("--mesh a dangling link", "mesh", ["run", "2.1-ex2a", "--mesh", "m.msh", "--out", OUT],
         dangling_mesh)

    # ------------------------------------------------------------ 8. signals at awkward moments
    api("SIGTERM from on_step at step 1", "signal",
        "import os, signal\ndef stop(step):\n    if step.n == 1:\n"
        "        os.kill(os.getpid(), signal.SIGTERM)\nrun(problem(T=0.04), on_step=stop)",
        expect="interrupted", fast=False)
    # SIGINT as an interactive session has it (a job started in the background ignores it)
    api("SIGINT while the load is built (set-up)", "signal",
        "import os, signal\nsignal.signal(signal.SIGINT, signal.default_int_handler)\n"
        "def load(x, t):\n    os.kill(os.getpid(), signal.SIGINT)\n"
        "    return ufl.as_vector((t, 0.0))\n"
        "try:\n    run(problem(traction=load))\nexcept KeyboardInterrupt:\n"
        "    print('damage-dolfinx: stopped by SIGINT', file=sys.stderr)\n    sys.exit(130)",
        expect="interrupted")
    api("SIGINT in converge at the coarse level", "signal",
        "import os, signal\nsignal.signal(signal.SIGINT, signal.default_int_handler)\n"
        "calls = []\ndef load(x, t):\n    calls.append(1)\n"
        "    if len(calls) == 4:\n        os.kill(os.getpid(), signal.SIGINT)\n"
        "    return ufl.as_vector((10 * t, 0.0))\n"
        "try:\n    dd.converge(problem(traction=load), 'o', n=[2], k=[0.01], ref_n=4, "
        "ref_k=0.005, progress=False)\nexcept KeyboardInterrupt:\n"
        "    print('damage-dolfinx: stopped by SIGINT', file=sys.stderr)\n    sys.exit(130)",
        expect="interrupted", fast=False)

    # ------------------------------------------------------------ 9. non-finite sources
    for ex, extra in (("2.3-ex1", ["--n", "4", "--k", "0.25", "--T", "0.5"]),
                      ("3.1-ex1", ["--n", "4", "--k", "0.125", "--T", "0.25"]),
                      ("3.2-ex1", ["--n", "4", "--k", "0.01", "--T", "0.02"]),
                      ("3.3-ex1", ["--n", "4", "--k", "0.5", "--T", "1"])):
        case(f"{ex} --set lam_u=1e300", "state",
             ["run", ex, *extra, "--no-figures", "--quiet", "--set", "lam_u=1e300",
              "--out", OUT], expect="failed", fast=False)

    # ------------------------------------------------------------ 10. weak messages
    parent_is_file = prepared(write={"p": b"the user's file\n"})
    case("--out below a file of the user's", "folder", [*run, "--out", "p/o"], parent_is_file)
    api("T=np.float32(0.02) (a NumPy float32)", "api",
        "run(problem(T=np.float32(0.02), k=np.float32(0.01)))", expect="ok", fast=False)
    api("boundaries with NumPy tags", "api",
        "run(problem(boundaries={'clamped': np.int32(1), 'traction': np.int64(2), "
        "'bilateral': np.uint8(3)}))", expect="ok", fast=False)

    # ------------------------------------------------------------ 11. sweep plots, dd.steps
    api("sweep(plot='bogus'): refused before any run", "sweep",
        "dd.sweep(problem(), 'o', {'kappa': [1.0, 2.0]}, plot='bogus', progress=False)")
    api("sweep(plot='contact_normal_force') of a problem with a bilateral part", "sweep",
        "dd.sweep(problem(), 'o', {'kappa': [1.0, 2.0]}, plot='contact_normal_force', "
        "progress=False)", expect="ok", fast=False,
        verify=lambda w: None if (w / OUT / "sweep.png").is_file() else "no sweep.png")
    failed_line = ("except RuntimeError as exc:\n    s = json.load(open('o/summary.json'))\n"
                   "    print(f'damage-dolfinx: failed: {exc} (summary: {s[\"status\"]})', "
                   "file=sys.stderr)\n    sys.exit(3 if s['status'] == 'failed' else 1)")
    with_body = ("with dd.steps(problem(T=0.04), 'o', figures=False, progress=False) as r:\n"
                 "    for step in r:\n        if step.n == 1{rank}:\n"
                 "            raise RuntimeError('my own check fails')\n")
    api("steps(): the with-body raising at step 1: the summary says failed", "api",
        "import json\ntry:\n" + "".join("    " + line + "\n" for line in
                                       with_body.format(rank="").splitlines()) + failed_line,
        expect="failed", fast=False)
    api("steps(): a break in the with-body at step 2: stopped", "api",
        "with dd.steps(problem(T=0.04), 'o', figures=False, progress=False) as r:\n"
        "    for step in r:\n        if step.n == 2:\n            break",
        expect="ok", fast=False, verify=summary_check("stopped", 2))
    api("2 ranks: steps() with-body raising on rank 1 only at step 1", "mpi",
        with_body.format(rank=" and MPI.COMM_WORLD.rank == 1"), expect="failed", fast=False,
        ranks=2)
    api("2 ranks: a plain steps() loop raising on rank 1 only at step 1", "mpi",
        "try:\n    for step in dd.steps(problem(T=0.04), 'o', figures=False, progress=False):\n"
        "        if step.n == 1 and MPI.COMM_WORLD.rank == 1:\n"
        "            raise RuntimeError('my own check fails')\n"
        "except RuntimeError as exc:\n    if MPI.COMM_WORLD.rank == 0:\n"
        "        print(f'damage-dolfinx: failed: {exc}', file=sys.stderr)\n    sys.exit(3)",
        expect="failed", fast=False, ranks=2)


if __name__ == "__main__":
    # these cases run through bad_inputs.py (its harness, folders and table); this entry point
    # only says so, and runs them when asked
    import argparse
    import runpy
    from pathlib import Path
    parser = argparse.ArgumentParser(
        description="The held-out rows of the bad-input table; they run through bad_inputs.py "
                    "(this runs it with --start 188, the rows of this file).")
    parser.parse_args()
    sys.argv = [str(Path(__file__).with_name("bad_inputs.py")), "--start", "188"]
    runpy.run_path(sys.argv[0], run_name="__main__")
