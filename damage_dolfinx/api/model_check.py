"""A model's self-test, :func:`check_model`: what a researcher runs on a model of their own
before trusting it (and what the package's models pass in the tests).

In a few steps on a small mesh it checks, each by name, with what to fix when it fails:

``contracts``
    the declarations against what the model builds (models/contracts.py: old_state and update
    name Functions, the package blocks' previous state is declared, what a step starts from is
    checkpointed);
``prefixes``
    each sub-step's PETSc prefix is the one its solver uses;
``run``
    the steps run and the state check after every step passes (every Function the model holds
    as state finite, zeta within its bounds);
``finite``
    every field of the final state finite (fields_final.npz);
``history_columns``
    every declared history column is in history.csv and written at every step, and every scalar
    the model reports has its column;
``restart``
    a run stopped half-way and restarted from its checkpoint equals the uninterrupted run;
``serial_vs_2_ranks``
    2 ranks (mpirun) give the serial result (where mpirun is available and the problem can be
    made again in another process: a catalogue case, or ``script=`` the file defining it);
``stability_limit``
    a dynamic model's ``mesh_k_max()`` against the eigenvalue estimate of its explicit elastic
    term (``blocks.estimate_k_max`` with the data's E, nu, rho, m_visc): a declared limit above
    the estimate (or none) fails; the time step below the limit.
"""
from __future__ import annotations

import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from mpi4py import MPI

from damage_dolfinx.core.parameters import InputError

#: fields of two runs agree to this, relative to the field's largest value
AGREEMENT = 1e-10
#: a declared limit may exceed the closed-form estimate of the explicit elastic term by this
#: much (a scheme's exact limit with its damping, e.g. 3.1's, is up to a few % above it)
STABILITY_MARGIN = 0.1


@dataclass
class Check:
    name: str
    status: str          # "pass", "fail", "skipped"
    detail: str = ""
    fix: str = ""


@dataclass
class ModelCheck:
    """The report of :func:`check_model`: ``checks`` in order; ``ok`` when none failed."""
    model: str
    checks: list = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return all(c.status != "fail" for c in self.checks)

    def __getitem__(self, name) -> Check:
        return next(c for c in self.checks if c.name == name)

    def failed(self) -> list:
        return [c.name for c in self.checks if c.status == "fail"]

    def __str__(self):
        lines = [f"check_model {self.model}: {'OK' if self.ok else 'FAILED: ' + ', '.join(self.failed())}"]
        for c in self.checks:
            lines.append(f"  {c.status.upper():7s} {c.name}: {c.detail}")
            if c.status == "fail" and c.fix:
                lines.append(f"          fix: {c.fix}")
        return "\n".join(lines)


def _case_for(model):
    """A Problem, a case name, or a Model class -> what a run takes (a package model's class:
    its first catalogue example; an own class: its ``check_problem()`` classmethod)."""
    from damage_dolfinx.models.base import Model
    if not (isinstance(model, str) or hasattr(model, "checked") or isinstance(model, type)
            and issubclass(model, Model)):
        raise InputError("check_model takes a Problem, a catalogue case name, a model id or a "
                         f"Model class, got {type(model).__name__}")
    if isinstance(model, type) and issubclass(model, Model):
        if hasattr(model, "check_problem"):
            return model.check_problem()
        import damage_dolfinx.catalogue  # noqa: F401 (registers the examples)
        from damage_dolfinx.catalogue.examples import catalogue
        for case in catalogue().values():
            if getattr(case, "model", None) == model.id and "3d" not in case.id:
                return case.id
        raise InputError(f"check_model: give a Problem with model {model.id} (or define its "
                         "classmethod check_problem())")
    return model


#: the run folders check_model writes in its ``out``
RUN_FOLDERS = ("whole", "restarted", "two_ranks")


def _check_arguments(out, steps, n, mpi, script, name, comm):
    """check_model's arguments, before any work (one InputError naming the first bad one)."""
    from damage_dolfinx.core import validation
    validation.arguments(n=n, comm=comm)
    validation.whole("steps", steps, low=2)  # (a restart half-way needs two steps)
    validation.flag("mpi", mpi)
    validation.text("name", name)
    if out is not None:
        validation.path("out", out)
        if Path(out).exists() and not Path(out).is_dir():
            raise InputError(f"out {str(out)!r} is a file, not a folder")
    if script is not None:
        validation.path("script", script)
        if not Path(script).is_file():
            raise InputError(f"script {str(script)!r} is not a file (give the file that "
                             "defines the problem, e.g. script=__file__)")


def _model_of_id(model):
    """A registered model's id (e.g. '3.1') as its class; anything else unchanged."""
    if isinstance(model, str):
        from damage_dolfinx.models import registry
        if model in registry.MODELS:
            return registry.model(model)
    return model


def _fields(folder) -> dict:
    with np.load(Path(folder) / "fields_final.npz") as data:
        return {k: data[k] for k in data.files}


def _differ(a: dict, b: dict) -> tuple:
    """(largest relative difference, its field) over the fields of a (coordinates excluded)."""
    worst = (0.0, "")
    for name in a:
        if name.endswith("_coords") or name not in b:
            continue
        if a[name].shape != b[name].shape:
            return math.inf, name
        scale = max(float(np.abs(a[name]).max()) if a[name].size else 0.0, 1e-300)
        d = float(np.abs(a[name] - b[name]).max()) / scale if a[name].size else 0.0
        worst = max(worst, (d, name))
    return worst


def check_model(model, out=None, steps=4, n=None, mpi=True, script=None, name="problem",
                comm=MPI.COMM_WORLD) -> ModelCheck:
    """Check a model in ``steps`` steps on a small mesh (level ``n``; None: the problem's).

    ``model``: a :class:`~damage_dolfinx.Problem` with the model, a catalogue case name, or a
    Model class or a registered model's id (a package model: its first catalogue example). ``out``: the folder of the runs
    (None: a temporary one, removed after). ``mpi``: also compare with 2 ranks where mpirun is
    available; a Problem written in a script is made again there from ``script`` (the file;
    its variable ``name``), a case name as it is. Returns a :class:`ModelCheck` (printed on
    rank 0 by the caller: ``print(report)``)."""
    from damage_dolfinx.models import contracts
    from damage_dolfinx.runtime.cases import resolve
    from damage_dolfinx.runtime.runner import ColumnError, run
    from damage_dolfinx.numerics.solvers import ConvergenceError
    _check_arguments(out, steps, n, mpi, script, name, comm)
    case = _case_for(_model_of_id(model))
    if isinstance(case, str):
        import damage_dolfinx.catalogue  # noqa: F401 (registers the case names)
    problem = resolve(case)
    temporary = out is None
    if temporary:
        out = Path(comm.bcast(tempfile.mkdtemp(prefix="check_model_") if comm.rank == 0 else None))
    out = Path(out)
    if not temporary:  # its run folders, before any work: nothing of the user's is touched
        from damage_dolfinx.runtime.runfolder import claim_folder
        for sub in RUN_FOLDERS:
            claim_folder(out / sub, "run", set(), False, True, comm, apply=False)
    report = ModelCheck(str(getattr(problem, "id", case)))
    add = lambda *a: report.checks.append(Check(*a))  # noqa: E731
    try:
        configured = problem.configure(n, None, None, None, None, None, comm)
        k = configured.time.k
        T = steps * k
        n_run = configured.n
        configured = problem.configure(n_run, k, T, None, None, None, comm)
        from damage_dolfinx.models.registry import model as model_of
        wrong = contracts.declaration_problems(model_of(configured.model))
        if wrong:  # the form of a declaration: the model is not built
            add("contracts", "fail", wrong[0], "change the declaration the message names")
            for name_ in ("prefixes", "stability_limit", "run", "finite", "history_columns",
                          "restart", "serial_vs_2_ranks"):
                add(name_, "skipped", "not run: the model is refused before it is built")
            return report
        from damage_dolfinx.numerics.stability_bound import exact_estimates
        with exact_estimates():  # the eigensolved limit, not only a cheap bound below it
            stepper = problem.build(comm, n_run, k, T, configured=configured, contracts=False)
        report.model = f"{stepper.id} ({report.model}, n = {n_run}, k = {k:g}, {steps} steps)"
        # -- contracts and prefixes
        found = contracts.problems(stepper)
        prefix = [m for what, m in found if what == "prefixes"]
        other = [m for what, m in found if what != "prefixes"]
        add("contracts", "fail" if other else "pass", other[0] if other else
            f"state checked after every step: {', '.join(n for n, _ in contracts.state_functions(stepper))}",
            "change the declaration the message names" if other else "")
        add("prefixes", "fail" if prefix else "pass", prefix[0] if prefix else
            ", ".join(f"{s.name}: {s.prefix or '(none)'}" for s in stepper.scheme()),
            "declare the prefix its solver uses" if prefix else "")
        _stability(report, stepper, k)
        declared = list(stepper.extra_history_columns)
        del stepper
        if found:
            for name_ in ("run", "finite", "history_columns", "restart", "serial_vs_2_ranks"):
                add(name_, "skipped", "not run: the model is refused before any step (contracts)")
            return report
        # -- the uninterrupted run
        options = dict(n=n_run, k=k, progress=False, figures=False, overwrite=True, comm=comm)
        whole = out / "whole"
        try:
            summary = run(problem, whole, T=T, checkpoint_every=1, **options)
            add("run", "pass" if summary["status"] == "completed" else "fail",
                f"{summary['status']} after {summary['steps_done']} steps")
            ran = True
        except ColumnError as exc:
            add("run", "fail", str(exc), "declare every scalar in history_columns")
            add("history_columns", "fail", str(exc), "declare every scalar in history_columns "
                "(or declared_columns(problem, dim)) and write each after every step")
            ran = False
        except (ConvergenceError, InputError) as exc:
            add("run", "fail", f"{type(exc).__name__}: {exc}",
                "the state check names the field; look at the sub-step that writes it")
            ran = False
        if not ran:
            for name_ in ("finite", "history_columns", "restart", "serial_vs_2_ranks"):
                if name_ not in [c.name for c in report.checks]:
                    add(name_, "skipped", "not run: the run failed")
            return report
        final = _fields(whole)
        bad = [k_ for k_, v in final.items() if v.dtype.kind in "fc" and not np.isfinite(v).all()]
        add("finite", "fail" if bad else "pass",
            f"not finite: {', '.join(bad)}" if bad else f"{len(final)} arrays of the final state",
            "" if not bad else "the field named is written with NaN/Inf by a sub-step")
        _columns(report, declared, whole)
        # -- checkpoint and restart against the uninterrupted run
        half = max(1, steps // 2)
        if not summary.get("checkpoint", True) or not (whole / "checkpoint.npz").exists():
            add("restart", "skipped", "the model has no checkpoints (checkpoint_supported)")
        else:
            resumed = out / "restarted"
            fix = ("a Function the step reads from the previous step is not checkpointed: put "
                   "it in old_state (it is then checkpointed) or in checkpoint_fields")
            run(problem, resumed, T=half * k, checkpoint_every=1, **options)
            try:  # a state left out of the checkpoint may also make the restarted run fail
                run(problem, resumed, T=T, restart=True, **{**options, "overwrite": False})
            except (ConvergenceError, InputError) as exc:
                add("restart", "fail", f"the run restarted at step {half} failed: "
                    f"{type(exc).__name__}: {exc}", fix)
            else:
                d, where = _differ(final, _fields(resumed))
                add("restart", "pass" if d <= AGREEMENT else "fail",
                    f"restarted at step {half}: largest relative difference {d:.2e} "
                    f"({where or '-'})", fix)
        _parallel(report, case, problem, script, name, mpi, comm, out, n_run, k, T, final)
        return report
    finally:
        if temporary and comm.rank == 0:
            shutil.rmtree(out, ignore_errors=True)


def _columns(report, declared, folder):
    """Every declared column in history.csv and written in every row (the run itself refuses
    a scalar without a column: ColumnError)."""
    import csv
    with open(folder / "history.csv") as f:
        rows = list(csv.DictReader(f))
    header = list(rows[0].keys()) if rows else []
    missing = [c for c in declared if c not in header]
    steps = [r for r in rows if r.get("step") not in ("0", None)]  # t = 0 has no step
    empty = [c for c in declared if c in header and any(r[c] in ("", None) for r in steps)]
    bad = missing + empty
    report.checks.append(Check(
        "history_columns", "fail" if bad else "pass",
        (f"declared but {'missing' if missing else 'not written at every step'}: "
         f"{', '.join(bad)}") if bad else
        f"{len(rows)} rows; the model's columns: {', '.join(declared) or '(none)'}",
        "write each declared column after every step (scalars())" if bad else ""))


def _stability(report, stepper, k):
    from damage_dolfinx.models import contracts
    if not stepper.dynamic:
        limit = type(stepper).k_max(stepper.params)
        report.checks.append(Check("stability_limit", "pass" if k <= limit else "fail",
                                   f"quasistatic, k_max = {limit:g} (closed form), k = {k:g}",
                                   "a smaller k"))
        return
    try:
        declared = contracts.mesh_k_max(stepper)
    except contracts.ContractError as exc:
        report.checks.append(Check("stability_limit", "fail", str(exc),
                                   "implement mesh_k_max(self) (blocks.estimate_k_max)"))
        return
    p, x = stepper.params, stepper.params.extra
    if not all(key in x for key in ("rho", "m_visc")):
        report.checks.append(Check("stability_limit", "skipped",
                                   f"mesh_k_max() = {declared:g}; no rho and m_visc in the data "
                                   "for the eigenvalue estimate"))
        return
    from damage_dolfinx.numerics.stability import estimate_k_max
    V = stepper.u.function_space
    estimate = float(estimate_k_max(V, p.E, p.nu, float(x["rho"]), float(x["m_visc"])))
    ok = declared <= estimate * (1 + STABILITY_MARGIN) and k <= declared
    report.checks.append(Check(
        "stability_limit", "pass" if ok else "fail",
        f"mesh_k_max() = {declared:.6g}, eigenvalue estimate of the explicit elastic term "
        f"{estimate:.6g} (ratio {declared / estimate:.3g}; contact terms lower it, the "
        f"scheme's own formula may differ by {STABILITY_MARGIN:.0%}), k = {k:g}",
        "" if ok else ("mesh_k_max() must not exceed the estimate: compute it with "
                       "blocks.estimate_k_max (with the contact terms)" if declared > estimate
                       * (1 + STABILITY_MARGIN) else "a smaller k")))


def _parallel(report, case, problem, script, name, mpi, comm, out, n_run, k, T, final):
    if not mpi:
        report.checks.append(Check("serial_vs_2_ranks", "skipped", "mpi=False"))
        return
    if comm.size > 1:
        report.checks.append(Check("serial_vs_2_ranks", "skipped",
                                   f"already on {comm.size} ranks"))
        return
    if shutil.which("mpirun") is None:
        report.checks.append(Check("serial_vs_2_ranks", "skipped", "no mpirun"))
        return
    if isinstance(case, str):
        make = (f"import damage_dolfinx.catalogue; case = {case!r}")
    elif script is not None:
        make = (f"import runpy; case = runpy.run_path({str(script)!r}, "
                f"run_name='check_model')[{name!r}]")
    else:
        report.checks.append(Check("serial_vs_2_ranks", "skipped",
                                   "a Problem written in a script: give script=__file__ (and "
                                   "name=, its variable) to compare with 2 ranks"))
        return
    folder = out / "two_ranks"
    code = (f"{make}; import damage_dolfinx as dd; dd.run(case, {str(folder)!r}, n={n_run!r}, "
            f"k={k!r}, T={T!r}, progress=False, figures=False, overwrite=True)")
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1", OMP_NUM_THREADS="1",
               PRTE_MCA_rmaps_default_mapping_policy=":oversubscribe")
    proc = subprocess.run(["mpirun", "-n", "2", sys.executable, "-c", code], env=env,
                          capture_output=True, text=True, timeout=900)
    if proc.returncode != 0:
        tail = (proc.stderr.strip().splitlines() or ["(no output)"])[-1]
        report.checks.append(Check("serial_vs_2_ranks", "fail", f"2 ranks failed: {tail}",
                                   "run the problem under mpirun -n 2 and read its error"))
        return
    d, where = _differ(final, _fields(folder))
    report.checks.append(Check(
        "serial_vs_2_ranks", "pass" if d <= AGREEMENT else "fail",
        f"largest relative difference {d:.2e} ({where or '-'})",
        "a rank-dependent computation: reduce over ranks (allreduce) what the step uses, use "
        "owned values only"))
