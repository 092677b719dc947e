"""Bad input on the newest surfaces, tried as careful users and reviewers would: a user's
callback deciding on one rank only, defaults that could replace an earlier result, values of
the wrong type or out of range (bools, NaN, infinities, underflows, repeated settings, a model's
own limit and history values, plugins that exit or raise), fingerprints and caches that must be
verified (a model's code, where each tag lies, an older fingerprint, a stored stability limit
edited), meshes and mesh families that do not hold what they claim, and stop signals at every
moment of a command. Writes bad_inputs_surfaces.json and bad_inputs_surfaces.md beside this
script.

    python benchmarks/faults/bad_inputs_surfaces.py [--only ID ...] [--fast] [--out DIR]

Each case runs through the harness of bad_inputs.py (its folders, its outcome classes: refused,
failed, warned, ok, interrupted, and the ones that must never happen); a case lists the
outcomes it accepts (a signal that arrives after the command has finished finds it ended: "ok"
with the status "completed" is as clean as "interrupted"). The fast cases run in
tests/test_bad_inputs_surfaces.py; cases marked slow (mpirun, signals, studies, own processes)
run here.

Classes of defect (``kind``): hang, data loss (an earlier result replaced or a user's file
touched), silent (a run that completed where the input was wrong, or a wrong summary),
ignored (an input that had no effect), traceback (a traceback or a crash), other.
"""
import argparse
import importlib.util
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
_spec = importlib.util.spec_from_file_location("bad_inputs", HERE / "bad_inputs.py")
bi = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(bi)

OUT, prepared, summary_check = bi.OUT, bi.prepared, bi.summary_check
none = prepared()

#: what the API cases add to bad_inputs.API_PRELUDE: own models (subclasses of the 2.1 model),
#: meshes with tags where the case wants them, a script's way of reporting a user's error
EXTRA_PRELUDE = '''
import json
import os
from damage_dolfinx import compat
from damage_dolfinx.models.elastic_2_1 import ElasticDamage


def tagged(comm, n, where):
    """A 2 x 0.5 rectangle of 4n x n cells with facet tags {tag: locator(x)} (any facet, not
    only boundary ones)."""
    from dolfinx import mesh as dm
    m = dm.create_rectangle(comm, [np.array([0.0, 0.0]), np.array([2.0, 0.5])], [4 * n, n])
    m.topology.create_connectivity(1, 2)
    idx, val = [], []
    for tag, locate in where.items():
        found = dm.locate_entities(m, 1, locate)
        idx.append(found)
        val.append(np.full(len(found), tag, dtype=np.int32))
    idx, val = np.concatenate(idx), np.concatenate(val)
    order = np.argsort(idx)
    return m, compat.meshtags(m, 1, idx[order].astype(np.int32), val[order])


left = lambda x: np.isclose(x[0], 0.0)
right = lambda x: np.isclose(x[0], 2.0)
bottom = lambda x: np.isclose(x[1], 0.0)
middle = lambda x: np.isclose(x[0], 1.0)


def failing(fn):
    """Run fn(); a user's error: one line with the summary's status, exit 3 if 'failed'."""
    try:
        fn()
    except Exception as exc:
        s = json.load(open('o/summary.json'))
        if MPI.COMM_WORLD.rank == 0:
            print(f"damage-dolfinx: failed: {type(exc).__name__}: {exc} (summary: "
                  f"{s['status']})", file=sys.stderr, flush=True)
        sys.exit(3 if s["status"] == "failed" else 1)
'''
PRELUDE = bi.API_PRELUDE + EXTRA_PRELUDE

#: cases of the table and what each accepts
CASES: list = []


def case(id_, cls, args, setup=none, expect="refused", fast=True, code=None, verify=None,
         ranks=1, own_process=False, signal_at=None, env=None):
    """One row: ``expect`` an outcome or a tuple of the accepted ones; ``own_process``: the
    API case needs a process of its own (the script's end matters); ``signal_at`` = (signal
    name, seconds): the command gets that signal then; ``env``: extra environment."""
    CASES.append(dict(id=id_, cls=cls, args=args, setup=setup, expect=expect, fast=fast,
                      code=code, verify=verify, ranks=ranks, own_process=own_process,
                      signal_at=signal_at, env=env))


def api(id_, cls, code, expect="refused", fast=True, first=None, **kw):
    setup = kw.pop("setup", none)
    if first is not None:  # an earlier run of the API, made before the case
        def setup(work, bases, code=PRELUDE + first, base=setup):
            made = base(work, bases)
            status, err = bi._api_in_process(code, work)
            if status != 0:
                raise RuntimeError(f"the earlier run of the case failed: {err}")
            return made
    case(id_, cls, ["<api>"], setup, expect, fast, code=PRELUDE + code, **kw)


RUN = ["run", "2.1-ex1", "--n", "5", "--k", "0.25", "--no-figures", "--quiet"]
CONV = ["converge", "2.1-ex1", "--ref-n", "10", "--ref-k", "0.125", "--n", "5", "--k", "0.25",
        "--quiet"]
SWEEP = ["sweep", "2.1-ex1", "--n", "5", "--k", "0.25", "--no-figures", "--quiet", "--set",
         "kappa=1,2"]
T4 = "problem(T=0.04)"  # 4 steps


def on_step_case(id_, body, expect, ranks=1, fast=False, verify=None):
    """dd.run with an on_step of the user's (``body``: its code, ``step`` and ``rank`` known)."""
    code = ("rank = MPI.COMM_WORLD.rank\ndef cb(step):\n" + "".join(
        f"    {line}\n" for line in body.splitlines()) +
        f"failing(lambda: run({T4}, on_step=cb))")
    api(id_, "callbacks", code, expect, fast=fast and ranks == 1, ranks=ranks, verify=verify)


# ============================================================== 1. callbacks: collective
on_step_case("on_step returns a NumPy array of two values", "return np.array([1, 2])",
             "failed", fast=True)
on_step_case("on_step returns an object whose truth raises",
             "class Odd:\n    def __bool__(self):\n        raise ValueError('no truth')\n"
             "return Odd()", "failed", fast=True)
on_step_case("on_step calls sys.exit(0) at step 1",
             "if step.n == 1:\n    sys.exit(0)", "failed", fast=True)
on_step_case("on_step calls sys.exit(3) at step 0", "if step.n == 0:\n    sys.exit(3)",
             "failed", fast=True)
on_step_case("on_step returns a string 'stop' at step 2 (a true value: stopped)",
             "return 'stop' if step.n == 2 else None", "ok", fast=True,
             verify=summary_check("stopped", 2))
on_step_case("on_step returns np.bool_(True) at step 1",
             "return np.bool_(step.n == 1)", "ok", fast=True,
             verify=summary_check("stopped", 1))
on_step_case("on_step raises at the last step", "if step.n == 4:\n    raise KeyError('mine')",
             "failed", fast=True)
for r, n in ((0, 1), (1, 1), (1, 0), (0, 3)):
    on_step_case(f"2 ranks: on_step returns True on rank {r} only at step {n}",
                 f"return rank == {r} and step.n == {n}", "warned", ranks=2)
for r, n in ((0, 1), (1, 2), (1, 0)):
    on_step_case(f"2 ranks: on_step raises on rank {r} only at step {n}",
                 f"if rank == {r} and step.n == {n}:\n    raise RuntimeError('rank {r}')",
                 "failed", ranks=2)
on_step_case("2 ranks: on_step returns a NumPy array on rank 1 only",
             "return np.array([1, 2]) if rank == 1 else None", "failed", ranks=2)
on_step_case("2 ranks: on_step calls sys.exit(0) on rank 1 only at step 1",
             "if rank == 1 and step.n == 1:\n    sys.exit(0)", "failed", ranks=2)
on_step_case("3 ranks: on_step returns True on rank 2 only at step 2",
             "return rank == 2 and step.n == 2", "warned", ranks=3)
on_step_case("3 ranks: on_step raises on rank 1 only at step 1",
             "if rank == 1 and step.n == 1:\n    raise RuntimeError('rank 1')", "failed",
             ranks=3)

STEPS = "dd.steps(problem(T=0.04), 'o', figures=False, progress=False)"
api("steps(): iterator left open when the script ends: stopped with a checkpoint",
    "callbacks", f"it = iter({STEPS})\nnext(it)\nnext(it)", "ok", fast=False,
    own_process=True, verify=summary_check("stopped", 1))
api("steps(): a break kept in a variable, the script then ends: stopped", "callbacks",
    f"s = {STEPS}\nfor step in s:\n    if step.n == 2:\n        break\nx = 1 + 1",
    "ok", fast=False, own_process=True, verify=summary_check("stopped", 2))
api("steps(): not iterated at all, the script ends", "callbacks", f"s = {STEPS}", "ok",
    fast=False, own_process=True)
api("2 ranks: steps() iterator left open on both ranks at the script's end", "callbacks",
    f"it = iter({STEPS})\nnext(it)\nnext(it)", "ok", ranks=2, fast=False,
    verify=summary_check("stopped", 1))
api("2 ranks: steps() with-body raising on rank 0 only at step 1", "callbacks",
    f"def body():\n    with {STEPS} as r:\n        for step in r:\n"
    "            if step.n == 1 and MPI.COMM_WORLD.rank == 0:\n"
    "                raise RuntimeError('mine')\nfailing(body)", "failed", ranks=2, fast=False)
api("2 ranks: steps() with-body break on rank 1 only at step 1", "callbacks",
    f"def body():\n    with {STEPS} as r:\n        for step in r:\n"
    "            if step.n == 1 and MPI.COMM_WORLD.rank == 1:\n"
    "                break\nfailing(body)", "failed", ranks=2, fast=False)
api("2 ranks: plain steps() loop break on rank 1 only at step 2", "callbacks",
    f"def body():\n    for step in {STEPS}:\n"
    "        if step.n == 2 and MPI.COMM_WORLD.rank == 1:\n            break\n"
    "failing(body)", "failed", ranks=2, fast=False)
api("2 ranks: steps() iterator left open on rank 1 only, rank 0 finishes", "callbacks",
    f"def body():\n    s = {STEPS}\n    for step in s:\n"
    "        if step.n == 1 and MPI.COMM_WORLD.rank == 1:\n            break\n"
    "failing(body)", ("failed", "ok"), ranks=2, fast=False)

# ============================================================== 2. defaults never destroy
CONVERGE = ("dd.converge(problem(), 'o', n=[2], k=[0.01], ref_n=4, ref_k=0.005, "
            "progress=False{})")
api("converge twice into one folder (API defaults)", "defaults", CONVERGE.format(""),
    first=CONVERGE.format(""), fast=False)
api("converge twice, the second with other levels", "defaults",
    "dd.converge(problem(), 'o', n=[2], k=[0.02], ref_n=4, ref_k=0.005, progress=False)",
    first=CONVERGE.format(""), fast=False)
api("converge again with overwrite=True replaces it (asked)", "defaults",
    CONVERGE.format(", overwrite=True"), "ok", first=CONVERGE.format(""), fast=False)
api("converge into a run's folder", "defaults", CONVERGE.format(""), first="run(problem())")
api("run into a study's folder", "defaults", "run(problem())", first=CONVERGE.format(""),
    fast=False)
api("run twice into one folder", "defaults", "run(problem())", first="run(problem())")
api("steps twice into one folder", "defaults", f"next(iter({STEPS}))", first="run(problem())")
api("run with restart=False, overwrite=False spelt out", "defaults",
    "run(problem(), restart=False, overwrite=False)", first="run(problem())")
api("sweep into a run's folder", "defaults",
    "dd.sweep(problem(), 'o', {'kappa': [1.0, 2.0]}, figures=False, progress=False)",
    first="run(problem())")
case("converge twice into one folder (command line)", "defaults", [*CONV, "--out", OUT],
     prepared("study"))
case("run into a study's folder (command line)", "defaults", [*RUN, "--out", OUT],
     prepared("study"))
case("converge into a run's folder (command line)", "defaults", [*CONV, "--out", OUT],
     prepared("run"))
case("converge into a sweep's folder (command line)", "defaults", [*CONV, "--out", OUT],
     prepared("sweep"))
case("sweep into a study's folder (command line)", "defaults", [*SWEEP, "--out", OUT],
     prepared("study"))

# ============================================================== 3. strict types and values
for key, value in (("E", "True"), ("E", "False"), ("nu", "True"), ("kappa", "np.True_"),
                   ("zeta_star", "True"), ("lam_D", "True"), ("E", "1e-320"),
                   ("kappa", "5e-324"), ("E", "None"), ("E", "[1e4]"), ("E", "'1e4x'"),
                   ("stop_at_zeta_star", "1"), ("stop_at_zeta_star", "0.0"),
                   ("L_trunc", "float('nan')"), ("E", "np.float64('nan')"),
                   ("kappa", "-np.inf"), ("q_star", "1e-310"), ("E", "1j"),
                   ("E", "np.array([1e4])"), ("nu", "np.bool_(False)")):
    api(f"params {key}={value}", "types", f"run(problem(params={{{key!r}: {value}}}))")
api("params L_trunc=inf (allowed: no truncation)", "types",
    "run(problem(params={'L_trunc': float('inf')}))", "ok", fast=False)
api("params E=np.int64(10000) (a NumPy integer is a number)", "types",
    "run(problem(params={'E': np.int64(10000)}))", "ok", fast=False)
for name, value in (("k", "1e-320"), ("T", "1e-320"), ("k", "5e-324"), ("k", "True"),
                    ("T", "True"), ("n", "True"), ("k", "float('nan')"),
                    ("T", "float('inf')"), ("k", "-0.0"), ("k", "np.float32('nan')")):
    api(f"run({name}={value})", "types", f"run(problem(), {name}={value})")
api("Problem(k=1e-320)", "types", "run(problem(k=1e-320))")
api("Problem(T=1e300, k=1e-300): T/k overflows", "types", "run(problem(T=1e300, k=1e-300))")
api("converge(ref_k=1e-320)", "types",
    "dd.converge(problem(), 'o', n=[2], k=[0.01], ref_n=4, ref_k=1e-320, progress=False)")
api("converge(k=[True])", "types",
    "dd.converge(problem(), 'o', n=[2], k=[True], ref_n=4, ref_k=0.005, progress=False)")
api("converge(n=[2.0])", "types",
    "dd.converge(problem(), 'o', n=[2.0], k=[0.01], ref_n=4, ref_k=0.005, progress=False)")
api("sweep grid kappa=[True, False]", "types",
    "dd.sweep(problem(), 'o', {'kappa': [True, False]}, figures=False, progress=False)")
api("sweep grid kappa=[1e-320, 1.0]", "types",
    "dd.sweep(problem(), 'o', {'kappa': [1e-320, 1.0]}, figures=False, progress=False)")
api("sweep grid kappa=[nan, 1.0]", "types",
    "dd.sweep(problem(), 'o', {'kappa': [float('nan'), 1.0]}, figures=False, progress=False)")
for flag, value in (("--k", "1e-320"), ("--T", "1e-320"), ("--k", "1e-310"),
                    ("--k", "4.9e-324"), ("--checkpoint-seconds", "1e-320")):
    case(f"run {flag} {value}", "types", ["run", "2.1-ex1", "--n", "5", "--no-figures",
                                          "--quiet", flag, value, "--out", OUT])
case("run --T 1e300 --k 1e-300 (T/k overflows)", "types",
     ["run", "2.1-ex1", "--n", "5", "--T", "1e300", "--k", "1e-300", "--quiet", "--out", OUT])
case("run --h 1e-320", "types", ["run", "2.1-ex2a", "--h", "1e-320", "--quiet", "--out", OUT])
case("converge --ref-k 1e-320", "types",
     ["converge", "2.1-ex1", "--ref-n", "10", "--ref-k", "1e-320", "--n", "5", "--k", "0.25",
      "--quiet", "--out", OUT])
case("converge --k 1e-320", "types",
     ["converge", "2.1-ex1", "--ref-n", "10", "--ref-k", "0.125", "--n", "5", "--k", "1e-320",
      "--quiet", "--out", OUT])
for sets in (["kappa=1", "kappa=2"], ["kappa=1", "kappa=1"], ["kappa=1", " kappa =2"],
             ["E=1e-320"], ["kappa=5e-324"], ["E=1e400"], ["kappa=nan"], ["=1"]):
    case("run --set " + " --set ".join(sets), "types",
         [*RUN, *[a for s in sets for a in ("--set", s)], "--out", OUT])
case("converge --set kappa=1 --set kappa=2", "types",
     [*CONV, "--set", "kappa=1", "--set", "kappa=2", "--out", OUT])
case("run 2.2-ex1 --friction-solver uzawa --set friction_solver=newton", "types",
     ["run", "2.2-ex1", "--n", "4", "--k", "0.25", "--T", "0.5", "--no-figures", "--quiet",
      "--friction-solver", "uzawa", "--set", "friction_solver=newton", "--out", OUT])
case("sweep --set kappa=1,2 --set kappa=3", "types",
     [*SWEEP, "--set", "kappa=3", "--out", OUT])

OWN = '''
class Mine(ElasticDamage):
    id = "mine_{name}"
    stability_limit = "own"
    {body}
'''


def own_model(name, body, call="run(problem(model=Mine))"):
    return OWN.format(name=name, body=body.replace("\n", "\n    ")) + call


for name, value in (("nan", "float('nan')"), ("neg", "-1.0"), ("zero", "0.0"),
                    ("text", "'big'"), ("none", "None"), ("bool", "True"),
                    ("tiny", "1e-320")):
    api(f"own model: k_max() returns {value}", "types",
        own_model(name, f"@classmethod\ndef k_max(cls, params):\n    return {value}"))
api("own model: k_max() returns inf (no limit)", "types",
    own_model("inf", "@classmethod\ndef k_max(cls, params):\n    return float('inf')"), "ok",
    fast=False)
ITS = ('''def scheme(self):
    import dataclasses
    first, second = super().scheme()
    solve = second.solve
    return first, dataclasses.replace(second, solve=lambda: (solve(), {0})[1])''')
for value, expect in (("'ok'", "failed"), ("True", "failed"), ("[3]", "failed"),
                      ("None", "ok")):
    api(f"own model: an iteration count {value}", "types",
        own_model(f"its{len(value)}{value[:1].isalpha()}", ITS.format(value),
                  "failing(lambda: run(problem(model=Mine)))"), expect, fast=expect != "ok")
api("own model: a scalar 'high' in history", "types",
    own_model("scal", "def scalars(self):\n    return {**super().scalars(), 'zeta_min': 'high'}",
              "failing(lambda: run(problem(model=Mine)))"), "failed")

PLUGIN = ("import os, sys\nsys.dont_write_bytecode = True\nsys.path.insert(0, os.getcwd())\n"
          "from damage_dolfinx import cli\nos.environ['DAMAGE_DOLFINX_PLUGINS'] = '{name}'\n"
          "try:\n    status = cli.main(['list'])\nfinally:\n"
          "    os.environ.pop('DAMAGE_DOLFINX_PLUGINS')\nsys.exit(status)")
for name, body in (("exit0", "import sys\nsys.exit(0)\n"), ("exit1", "import sys\nsys.exit(1)\n"),
                   ("exittext", "import sys\nsys.exit('bye')\n"),
                   ("raises", "raise RuntimeError('plugin broken')\n"),
                   ("keyerror", "{}['x']\n"), ("syntax", "def (:\n"),
                   ("exitnone", "raise SystemExit\n"),
                   ("attr", "import damage_dolfinx\ndamage_dolfinx.nonexistent_thing\n")):
    module = f"plug_{name}"
    api(f"plugin that {body.strip().splitlines()[-1][:40]}", "types",
        PLUGIN.format(name=module), setup=prepared(write={f"{module}.py": body.encode()}))
api("plugin not found", "types", PLUGIN.format(name="plug_nowhere"))

# ============================================================== 4. fingerprints and caches
api("restart after editing the own model's code (same name)", "fingerprints",
    own_model("edit", "def end_step(self, stats):\n    super().end_step(stats)\n"
                      "    self.zeta.x.array[:] *= 1.0",
              "run(problem(model=Mine, T=0.04), restart=True)"),
    first=own_model("edit", "def end_step(self, stats):\n    super().end_step(stats)",
                    "run(problem(model=Mine))"), fast=False)
api("restart after editing a base class of the own model", "fingerprints",
    "class Base(ElasticDamage):\n    def end_step(self, stats):\n        super().end_step(stats)"
    "\n        x = 2\n" + own_model("base", "pass",
                                   "run(problem(model=Mine, T=0.04), restart=True)")
    .replace("class Mine(ElasticDamage)", "class Mine(Base)"),
    first="class Base(ElasticDamage):\n    def end_step(self, stats):\n"
          "        super().end_step(stats)\n" + own_model("base", "pass").replace(
              "class Mine(ElasticDamage)", "class Mine(Base)"), fast=False)
api("restart with the own model unchanged (accepted)", "fingerprints",
    own_model("same", "pass", "run(problem(model=Mine, T=0.04), restart=True)"), "ok",
    first=own_model("same", "pass"), fast=False)
SWAP = ("tagged(comm, n, {{1: {a}, 2: {b}, 3: bottom}})")
for a, b, what in (("right", "left", "the clamped and traction tags swapped, same counts"),
                   ("left", "middle", "the traction tag moved inside, same count")):
    api(f"restart, {what}", "fingerprints",
        f"run(problem(mesh=lambda comm, n: {SWAP.format(a=a, b=b)}, T=0.04), restart=True)",
        first=f"run(problem(mesh=lambda comm, n: {SWAP.format(a='left', b='right')}))",
        fast=False)
api("restart on the same tagged mesh (accepted)", "fingerprints",
    f"run(problem(mesh=lambda comm, n: {SWAP.format(a='left', b='right')}, T=0.04), "
    "restart=True)", "ok",
    first=f"run(problem(mesh=lambda comm, n: {SWAP.format(a='left', b='right')}))", fast=False)


def older_format(folder, drop=("model_code", "tagged_geometry")):
    """The checkpoint's fingerprint (checkpoint.npz and its copy checkpoint.json) as a
    format-3 checkpoint wrote it."""
    def change(arrays, meta):
        for fp in _fingerprints(meta):
            fp["version"] = 3
            for key in drop:
                fp.pop(key, None)
    bi.edit_checkpoint(folder / "checkpoint.npz", change)
    path = folder / "checkpoint.json"
    meta = json.loads(path.read_text())
    change(None, meta)
    path.write_text(json.dumps(meta))


def _fingerprints(value):
    if isinstance(value, dict):
        if "mesh_nodes" in value:
            yield value
        for v in value.values():
            yield from _fingerprints(v)
    elif isinstance(value, list):
        for v in value:
            yield from _fingerprints(v)


case("restart from a checkpoint of the older fingerprint format", "fingerprints",
     [*RUN, "--T", "2", "--restart", "--out", OUT], prepared("run", edit=older_format))
case("restart, the fingerprint's version field removed", "fingerprints",
     [*RUN, "--T", "2", "--restart", "--out", OUT],
     prepared("run", edit=lambda f: older_format(f, drop=("version",))))
case("restart, the checkpoint's fingerprint intact (accepted)", "fingerprints",
     [*RUN, "--T", "2", "--restart", "--out", OUT], prepared("run"), "ok", fast=False)

#: 3.1 Ex. 1 at n = 6 with the eigensolve forced, into the cache folder ./cache (the case's)
STABILITY = '''
from damage_dolfinx.catalogue import examples
from damage_dolfinx.geometries import GAMMA_C
from damage_dolfinx.numerics import stability, stability_bound
os.environ["DAMAGE_DOLFINX_CACHE_DIR"] = os.path.abspath("cache")
try:
    st = examples.get("3.1-ex1", "literal").build(MPI.COMM_WORLD, n=6, k=0.01, T=0.01,
                                                  overrides={"stability_check": "off"})
    ds = ufl.Measure("ds", domain=st.mesh, subdomain_data=st.data.geometry.facet_tags)
    def estimate():
        with stability_bound.exact_estimates():
            return stability.estimate_stability(st.v.function_space, st.params.E, st.params.nu,
                                                st.rho, st.m_visc, st.c_nu, ds(GAMMA_C), st.bcs)
    true = estimate()["k_max"]
    stability_bound._CACHE.clear()
    import glob
    path = glob.glob("cache/stability/*.json")[0]
    entry = json.load(open(path))
    EDIT
    json.dump(entry, open(path, "w"))
    got = estimate()
    if abs(got["k_max"] - true) > 1e-9 * true:
        print(f"damage-dolfinx: the stored k_max {got['k_max']} was believed (true {true})",
              file=sys.stderr)
        sys.exit(0)
finally:
    os.environ.pop("DAMAGE_DOLFINX_CACHE_DIR")
'''
for what, edit in (("k_max x100", "entry['k_max'] *= 100; entry['k_suggested'] *= 100"),
                   ("k_max Infinity", "entry['k_max'] = float('inf')"),
                   ("k_max x5", "entry['k_max'] *= 5; entry['k_suggested'] *= 5"),
                   ("omega2 / 100", "entry['omega2_max'] /= 100"),
                   ("its key changed", "entry['key'] = 'another'"),
                   ("k_max a text", "entry['k_max'] = 'big'"),
                   ("k_max NaN", "entry['k_max'] = float('nan')")):
    api(f"stability cache entry edited: {what}", "fingerprints", STABILITY.replace("EDIT", edit),
        "warned" if what not in ("k_max a text", "k_max NaN") else "ok",
        fast=False, verify=lambda w: None)
api("stability cache entry intact (used)", "fingerprints", STABILITY.replace("EDIT", "pass"), "ok",
    fast=False)

# ============================================================== 5. meshes and families
GMSH = '''
from damage_dolfinx.runtime.meshfile import _gmsh
g = _gmsh()
g.model.add("m")
occ = g.model.occ
{body}
g.option.setNumber("Mesh.MeshSizeMax", 0.3)
g.model.mesh.generate(2)
{after}
g.write("m.msh")
g.model.remove()
'''


def gmsh_file(body, after=""):
    def setup(work, bases):
        status, err = bi._api_in_process(PRELUDE + GMSH.format(body=body, after=after), work)
        if status != 0:
            raise RuntimeError(f"making the mesh failed: {err}")
        return ["m.msh"]
    return setup


SQUARE = ("r = occ.addRectangle(0, 0, 0, 1, 1)\n{rotate}occ.synchronize()\n"
          "g.model.addPhysicalGroup(2, [r], 10)\n"
          "cs = [t for _, t in g.model.getBoundary([(2, r)], oriented=False)]\n"
          "g.model.addPhysicalGroup(1, cs[:1], 1)\ng.model.addPhysicalGroup(1, cs[1:], 2)")
HALVES = ("a, b = occ.addRectangle(0, 0, 0, 1, 1), occ.addRectangle(1, 0, 0, 1, 1)\n"
          "occ.fragment([(2, a)], [(2, b)])\nocc.synchronize()\n"
          "g.model.addPhysicalGroup(2, {cells}, 10)\n"
          "cs = [t for _, t in g.model.getEntities(1)]\n"
          "inner = [c for c in cs if abs(occ.getCenterOfMass(1, c)[0] - 1) < 1e-9 and "
          "abs(occ.getCenterOfMass(1, c)[1] - 0.5) < 1e-9]\n"
          "lft = [c for c in cs if abs(occ.getCenterOfMass(1, c)[0]) < 1e-9]\n"
          "g.model.addPhysicalGroup(1, lft, 1)\n"
          "g.model.addPhysicalGroup(1, [c for c in cs if c not in lft + inner], 2)\n"
          "g.model.addPhysicalGroup(1, inner, 3)")
XZ = "occ.rotate([(2, r)], 0, 0, 0, 1, 0, 0, np.pi / 2)\n"
MESHES = {
    "in the x-z plane": gmsh_file(SQUARE.format(rotate=XZ)),
    "in the y-z plane": gmsh_file(SQUARE.format(
        rotate="occ.rotate([(2, r)], 0, 0, 0, 0, 1, 0, np.pi / 2)\n")),
    "tilted out of the x-y plane": gmsh_file(SQUARE.format(
        rotate="occ.rotate([(2, r)], 0, 0, 0, 1, 0, 0, 0.3)\n")),
    "with half its cells untagged": gmsh_file(HALVES.format(cells="[a]")),
    "of second-order triangles": gmsh_file(SQUARE.format(rotate=""),
                                           "g.model.mesh.setOrder(2)"),
}
for what, setup in MESHES.items():
    api(f"read_mesh: a 2-D mesh {what}", "meshes", "dd.read_mesh('m.msh', dim=2)",
        setup=setup, fast=False)
    case(f"run --mesh: a 2-D mesh {what}", "meshes",
         ["run", "2.1-ex1", "--mesh", "m.msh", "--k", "0.25", "--no-figures", "--quiet",
          "--out", OUT], setup, fast=False)
api("run on a mesh file with half its cells untagged", "meshes",
    "run(problem(mesh='m.msh', boundaries={'clamped': 1, 'traction': 2}, n=None))",
    setup=MESHES["with half its cells untagged"], fast=False)
api("run on a second-order mesh file", "meshes",
    "run(problem(mesh='m.msh', boundaries={'clamped': 1, 'traction': 2}, n=None))",
    setup=MESHES["of second-order triangles"], fast=False)
api("read_mesh: a 2-D square in the x-y plane (accepted)", "meshes",
    "dd.read_mesh('m.msh', dim=2)", "ok", setup=gmsh_file(SQUARE.format(rotate="")),
    fast=False)
api("a 2.1 bilateral tag on an interior line", "meshes",
    "run(problem(mesh=lambda comm, n: tagged(comm, n, {1: left, 2: right, 3: middle})))")
api("a 2.2 Tresca tag on an interior line", "meshes",
    "run(problem(model='2.2', mesh=lambda comm, n: tagged(comm, n, {1: left, 2: right, "
    "3: middle}), boundaries={'clamped': 1, 'traction': 2, 'tresca': 3}))")
api("a traction tag on an interior line", "meshes",
    "run(problem(mesh=lambda comm, n: tagged(comm, n, {1: left, 2: middle, 3: bottom})))")
api("a clamped tag half inside, half on the boundary", "meshes",
    "run(problem(mesh=lambda comm, n: tagged(comm, n, {1: lambda x: np.isclose(x[0], 0) | "
    "np.isclose(x[0], 1.0), 2: right, 3: bottom})))")
api("a Tresca tag on a gmsh file's interior curve", "meshes",
    "run(problem(model='2.2', mesh='m.msh', n=None, boundaries={'clamped': 1, "
    "'traction': 2, 'tresca': 3}))", setup=gmsh_file(HALVES.format(cells="[a, b]")),
    fast=False)
api("all tags on the boundary (accepted)", "meshes",
    "run(problem(mesh=lambda comm, n: tagged(comm, n, {1: left, 2: right, 3: bottom})))",
    "ok", fast=False)
FAMILY = ("dd.converge(problem(mesh={mesh}), 'o', n={n}, k=[0.01], ref_n={ref}, ref_k=0.005, "
          "progress=False)")
for what, fam, n, ref in (
        ("ignoring n", "lambda comm, n: mesh(comm, 2)", [2], 4),
        ("ignoring n, two levels", "lambda comm, n: mesh(comm, 3)", [2, 3], 6),
        ("coarser as n grows", "lambda comm, n: mesh(comm, max(1, 8 // n))", [2], 4),
        ("of another domain at the reference", "lambda comm, n: rectangle(comm, (0.0, 0.0), "
         "(2.0 if n < 4 else 3.0, 0.5), 4 * n, n, {1: side(0, 0.0), 2: side(0, 2.0 if n < 4 "
         "else 3.0), 3: side(1, 0.0)})", [2], 4),
        ("shifted at the coarse level", "lambda comm, n: rectangle(comm, (0.0 if n > 2 else "
         "1.0, 0.0), (2.0 if n > 2 else 3.0, 0.5), 4 * n, n, {1: side(0, 0.0 if n > 2 else "
         "1.0), 2: side(0, 2.0 if n > 2 else 3.0), 3: side(1, 0.0)})", [2], 4),
        ("the same mesh at every level (n ignored, nested sizes)",
         "lambda comm, n: mesh(comm, 4)", [2], 4)):
    api(f"converge: a family {what}", "meshes", FAMILY.format(mesh=fam, n=n, ref=ref),
        fast=False)
api("converge: a proper family (accepted)", "meshes",
    FAMILY.format(mesh="mesh", n=[2], ref=4), "ok", fast=False)

# ============================================================== 6. signals at every moment
for command, args in (("converge", CONV), ("run", RUN), ("sweep", SWEEP)):
    for name in ("SIGUSR1", "SIGTERM", "SIGINT"):
        for at in (0.3, 0.8, 1.6):
            case(f"{command}: {name} after {at} s", "signals", [*args, "--out", OUT],
                 expect=("interrupted", "ok"), fast=False, signal_at=(name, at))


# ---------------------------------------------------------------------------- running
def _signalled(case_, work):
    """The command in ``work`` with the case's signal sent at its time: (status, stderr)."""
    name, at = case_["signal_at"]
    env = dict(bi.ENV)
    proc = subprocess.Popen([sys.executable, "-m", "damage_dolfinx.cli", *case_["args"]],
                            cwd=work, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, preexec_fn=lambda: signal.signal(signal.SIGINT,
                                                                        signal.SIG_DFL))
    time.sleep(at)
    try:
        proc.send_signal(getattr(signal, name))
    except ProcessLookupError:
        pass
    try:
        _, err = proc.communicate(timeout=bi.TIMEOUT[0])
    except subprocess.TimeoutExpired:
        proc.kill()
        _, err = proc.communicate()
        return None, err
    return proc.returncode, err


def run_case(case_, bases, root: Path, runner=None) -> dict:
    """One case (bad_inputs.run_case, with the own-process and signal cases here); the
    result's ``pass``: its outcome is one the case accepts."""
    accepted = case_["expect"] if isinstance(case_["expect"], tuple) else (case_["expect"],)
    if case_.get("signal_at") or case_.get("own_process"):
        work = Path(tempfile.mkdtemp(dir=root))
        user = case_["setup"](work, bases)
        before = bi.snapshot(work)
        start = time.perf_counter()
        if case_.get("signal_at"):
            status, err = _signalled(case_, work)
            if status == 128 + signal.SIGUSR1:  # the table's class of a signal's status
                status = 143
        else:
            scripts = Path(tempfile.mkdtemp(dir=root))
            (scripts / "harness.py").write_text(bi.API_HARNESS)
            (scripts / "case.py").write_text(case_["code"])
            status, _, err = bi._subprocess(None, work, 1, [str(scripts / "harness.py"),
                                                            str(scripts / "case.py")])
        result = bi.classify(dict(case_, expect=accepted[0]), status, err, before,
                             bi.snapshot(work), user, work)
        if result["outcome"] == "ok" and case_.get("verify"):
            wrong = case_["verify"](work)
            if wrong:
                result.update(outcome="silently wrong result", message=wrong)
        result["seconds"] = round(time.perf_counter() - start, 1)
        shutil.rmtree(work, ignore_errors=True)
    else:
        kw = {} if runner is None else {"runner": runner}
        result = bi.run_case(dict(case_, expect=accepted[0]), bases, root, **kw)
    result["expected"] = " or ".join(accepted)
    result["pass"] = result["outcome"] in accepted
    return result


def kind(r) -> str:
    """hang, data loss, silent, ignored, traceback, other, or clean."""
    if r["pass"]:
        return "clean"
    outcome = r["outcome"]
    if outcome.startswith("no end"):
        return "hang"
    if outcome == "user file touched" or (r["class"] == "defaults" and outcome in
                                          ("ok", "warned")):
        return "data loss"
    if outcome == "traceback or crash":
        return "traceback"
    if outcome in ("ok", "warned", "silently wrong result"):
        return "silent" if r["class"] in ("fingerprints", "meshes", "callbacks") else "ignored"
    return "other"


def write_tables(results, out: Path, note=""):
    out.mkdir(parents=True, exist_ok=True)
    (out / "bad_inputs_surfaces.json").write_text(json.dumps(results, indent=1,
                                                             allow_nan=False) + "\n")
    kinds, by_class = {}, {}
    for r in results:
        kinds[kind(r)] = kinds.get(kind(r), 0) + 1
        by_class.setdefault(r["class"], [0, 0])
        by_class[r["class"]][0] += 1
        by_class[r["class"]][1] += r["pass"]
    lines = ["# Bad input on the newest surfaces", "",
             f"{len(results)} cases, {sum(r['pass'] for r in results)} clean. By class of "
             "defect: " + ", ".join(f"{k} {v}" for k, v in sorted(kinds.items())) + ". By "
             "surface (clean of cases): " + ", ".join(f"{c} {p}/{n}" for c, (n, p) in
                                                      by_class.items()) + ".", "",
             "Written by `python benchmarks/faults/bad_inputs_surfaces.py` (the harness and "
             "the outcome classes of bad_inputs.py; `o` is the output folder).", "", note,
             "", "| # | surface | case | exit | outcome (accepted) | message |",
             "|---|---|---|---|---|---|"]
    for i, r in enumerate(results, 1):
        mark = "" if r["pass"] else " **UNEXPECTED**"
        message = r["message"].replace("|", "\\|")[:200]
        lines.append(f"| {i} | {r['class']} | {r['id']} | {r['exit_status']} | "
                     f"{r['outcome']} ({r['expected']}){mark} | {message} |")
    (out / "bad_inputs_surfaces.md").write_text("\n".join(lines) + "\n")
    return kinds


def make_bases(root: Path) -> dict:
    return bi.make_bases(root, lambda a, cwd: bi._check(bi._subprocess(a, cwd)))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="+", help="case ids (substrings)")
    parser.add_argument("--fast", action="store_true", help="only the fast cases")
    parser.add_argument("--out", default=str(HERE), help="folder of the two tables")
    parser.add_argument("--timeout", type=float, default=120.0, help="seconds per case")
    parser.add_argument("--note", default="", help="a paragraph for the table's head")
    args = parser.parse_args()
    bi.TIMEOUT[0] = args.timeout
    cases = [c for c in CASES if (not args.only or any(s in c["id"] for s in args.only))
             and (c["fast"] or not args.fast)]
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        bases = make_bases(root)
        results = []
        for c in cases:
            r = run_case(c, bases, root)
            print(f"{kind(r):>9s} {r['outcome']:>12s} ({r['expected']}) exit "
                  f"{r['exit_status']} {r['id']}: {r['message'][:100]}", flush=True)
            results.append(r)
    kinds = write_tables(results, Path(args.out), args.note)
    print(f"{len(results)} cases, {sum(r['pass'] for r in results)} clean; by class: {kinds}")


if __name__ == "__main__":
    main()
