"""Convergence study against a fine reference solution (thesis Tables 2.1, 2.4, ...).

The reference run and all coarse runs advance in lockstep: whenever the reference reaches a
coarse run's next time level, that run takes its step, is transferred exactly to the nested
reference mesh (:func:`post.nested_transfer`, P1 or DG0) and its error is computed there,

    e(n, k) = max over common time levels of the sum of the stepper's ``error_components``
              (default ||u_ref - u_hk||_V + ||zeta_ref - zeta_hk||_Y; each problem sets the
              norm its thesis table uses, e.g. ||sigma||_Q for 2.4, ||v||_H for 3.1),

so no reference history is stored. Everything runs under MPI. By default (reference_ranks 1)
the reference runs serially on rank 0 and every cell serially on the other ranks,
which send their cells' nodal values to rank 0 without waiting for it; with ``--reference-ranks
all`` the reference and the cells n > SERIAL_CELL_MAX_N run on all ranks and the smaller cells
serially, shared out among all ranks. The norm is one product with a Gram matrix.
Outputs: ``errors.csv``, ``errors.md``, ``convergence.png`` (log-log error vs h + k with the
fitted rate) and ``summary.json``.
"""
from __future__ import annotations

import json
import sys
import time

import numpy as np
from mpi4py import MPI

from damage_dolfinx.runtime import io
from damage_dolfinx.core.parameters import InputError, TimeGrid
from damage_dolfinx.runtime.runner import Progress, solver_step
from damage_dolfinx.studies.convergence_tables import (fitted_rates, plot_convergence,  # noqa: F401
                                                      write_tables)
from damage_dolfinx.numerics.solvers import ConvergenceError
from damage_dolfinx.studies.convergence_cells import (  # noqa: F401 (SERIAL_CELL_MAX_N)
    SERIAL_CELL_MAX_N, _CoarseRun, _Transfers, _cell_geometry, _check_states, _component_norms,
    check_family,
    _error_definition, _norm_statement, _owners)

from damage_dolfinx.studies.convergence_resume import (SCHEMA, check_restart, level_fingerprints,
                                                       outputs_intact, previous_study)


def _check_levels(ref_n, ref_k, ns, ks):
    """Levels are positive, distinct and of the right type (before any division by them)."""
    for name, values, kind in (("--ref-n", [ref_n], int), ("--n", ns, int),
                               ("--ref-k", [ref_k], float), ("--k", ks, float)):
        for v in values:
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not v > 0 or \
                    (kind is int and v != int(v)) or v != v or v == float("inf"):
                raise InputError(f"{name}: every level must be a positive "
                                 f"{'whole ' if kind is int else 'finite '}number, got {v!r}")
        if len(set(values)) != len(values):
            raise InputError(f"{name}: the levels must be distinct, got "
                             f"{' '.join(f'{v:g}' for v in values)}")


def _structured(ex, n) -> bool:
    """Whether the family's mesh at level n is a structured grid (built on each rank alone: a
    coarse mesh, before any run)."""
    return ex.make_geometry(MPI.COMM_SELF, n, None).grid is not None


def _check_steps(ref_n, ref_k, ns, ks):
    """Coarse levels below the reference's, coarse steps multiples of its step (the nesting of
    the meshes is checked once they are built: _Transfers)."""
    for n in ns:
        if n >= ref_n:
            raise InputError(f"coarse mesh n = {n} must be coarser than the reference n = {ref_n}")
    for k in ks:
        ratio = k / ref_k
        if abs(ratio - round(ratio)) > 1e-8 * ratio or round(ratio) < 1:
            raise InputError(f"reference k = {ref_k} must divide every coarse k (k = {k})")


def study(example_id, out, ref_n=None, ref_k=None, ns=None, ks=None, T=None, overrides=None,
          progress=True, comm=MPI.COMM_WORLD, serial_max_n=SERIAL_CELL_MAX_N,
          reference_ranks=None, restart=False, overwrite=True) -> dict:
    """Run the study; returns the summary (errors per (n, k), fitted rates, wall times).

    ``reference_ranks`` (default: the catalogue's ``convergence["reference_ranks"]``, else 1):
    1 runs the reference serially on rank 0 and every coarse cell serially on the other ranks
    (the measurements on rank 0); "all" runs the reference and the cells n > SERIAL_CELL_MAX_N
    on all ranks, the smaller cells serially shared out among all ranks. On 2 cores the first
    is faster for every thesis study (benchmarks/README.md): a serial step uses
    PETSc's Cholesky and the serial-only zeta-linear matrices of 3.3, MUMPS on 2 ranks is no
    faster than that, and the second rank is free for the cells. A finer reference on many
    ranks wants "all".

    The folder follows the rules of a run (runfolder.claim_folder, manifest.json): a folder
    holding a run is refused, one holding a study unless ``overwrite`` (its listed files are
    replaced) or ``restart`` (nothing to do when it completed with these settings; studies keep
    no checkpoints, so an unfinished one runs again; settings or a run fingerprint of any level
    that differ are refused, naming them: convergence_resume.py). A solver failure or a non-finite error
    leaves summary.json with status "failed" and the error."""
    wall_start = time.perf_counter()
    from damage_dolfinx.runtime.runner import resolve
    ex = resolve(example_id, overrides)
    example_id = ex.id
    overrides = dict(overrides or {})
    if not ex.own:  # the thesis's own time steps run as the thesis ran them (warn above k_max)
        overrides.setdefault("stability_check", ex.params.extra.get("stability_check", "warn"))
    defaults = ex.convergence or {}
    if ex.n is None:
        raise InputError(f"example {example_id} has no mesh family; convergence studies need "
                         "one: meshes (comm, n) -> mesh at levels n (e.g. 2.1-ex1)")
    ref_n = defaults["ref_n"] if ref_n is None else ref_n  # 0 is refused, not the default
    ref_k = defaults["ref_k"] if ref_k is None else ref_k
    ns = list(defaults["n"] if ns is None else ns)
    ks = list(defaults["k"] if ks is None else ks)
    T = ex.T if T is None else T
    _check_levels(ref_n, ref_k, ns, ks)
    _check_steps(ref_n, ref_k, ns, ks)
    if not ex.own or _structured(ex, min(ns)):  # nested structured: every n divides ref_n
        for n in ns:
            if ref_n % n:
                raise InputError(f"coarse mesh n = {n} is not nested in the reference "
                                 f"n = {ref_n}")
    for n in ns + [ref_n]:
        ex.configure(n=n, k=ref_k, T=T, overrides=overrides)
    for k in ks:
        TimeGrid(k, T)
    out = io.prepare_output_dir(out, comm)
    settings = {"example": ex.id, "reading": ex.reading, "ref_n": ref_n, "ref_k": ref_k,
                "T": T, "n": ns, "k": ks,
                "parameters": json.loads(io.strict_json(
                    ex.configure(n=ref_n, k=ref_k, T=T, overrides=overrides).params.as_dict()))}
    # every level's fingerprint, checked by a restart (convergence_resume.py)
    settings["fingerprints"] = level_fingerprints(ex, comm, [ref_n] + ns, ref_k, T, overrides)
    previous = previous_study(out, comm)
    if restart and previous is not None:
        check_restart(previous, settings, out, ref_n)
        if previous.get("status") == "completed" and outputs_intact(out, previous, comm):
            if comm.rank == 0:
                print(f"damage-dolfinx: nothing to do: the study in {str(out)!r} completed "
                      "with these settings; its outputs are unchanged", flush=True)
            return previous
    from damage_dolfinx.runtime.runfolder import STUDY_FILES, RunLock, claim_folder
    lock = RunLock(out, comm)
    try:
        earlier = claim_folder(out, "study", STUDY_FILES, restart, overwrite, comm,
                               "a convergence study", apply=False)
        if earlier and restart and comm.rank == 0:
            why = "its outputs are damaged" if (previous or {}).get("status") == "completed" \
                else "it did not complete"
            print(f"damage-dolfinx: the study in {str(out)!r}: {why} and studies keep no "
                  "checkpoints: it runs again from the start", file=sys.stderr, flush=True)
        claimed = []

        def claim():  # after the set-up: a refused one leaves the folder untouched
            claim_folder(out, "study", STUDY_FILES, restart, overwrite, comm,
                         "a convergence study")
            claimed.append(True)
        return _study(ex, out, ref_n, ref_k, ns, ks, T, overrides, progress, comm, serial_max_n,
                      reference_ranks, defaults, wall_start, settings, claim, claimed, lock)
    finally:
        lock.release()


def _study(ex, out, ref_n, ref_k, ns, ks, T, overrides, progress, comm, serial_max_n,
           reference_ranks, defaults, wall_start, settings, claim, claimed, lock=None):
    failed = {"schema": SCHEMA, "status": "failed", **settings}
    try:
        return _lockstep(ex, out, ref_n, ref_k, ns, ks, T, overrides, progress, comm,
                         serial_max_n, reference_ranks, defaults, wall_start, settings, claim)
    except (ConvergenceError, InputError, io.OutputError) as exc:
        if not claimed:
            raise
        failed.update(error=str(exc), wall_time_s=time.perf_counter() - wall_start)
        if lock is not None and comm.rank == 0:
            lock.free_reserve()  # so that a full disk still takes the status
        try:
            io.write_json(out / "summary.json", failed, comm)
        except OSError:
            pass
        raise


def _lockstep(ex, out, ref_n, ref_k, ns, ks, T, overrides, progress, comm, serial_max_n,
              reference_ranks, defaults, wall_start, settings, claim):
    ref_serial = comm.size > 1 and (reference_ranks or defaults.get("reference_ranks", 1)) == 1
    ref_rank, ref_comm = (0, MPI.COMM_SELF) if ref_serial else (None, comm)
    ref = ex.build(ref_comm, n=ref_n, k=ref_k, T=T, overrides=overrides) \
        if not ref_serial or comm.rank == ref_rank else None
    norms = _component_norms(ref) if ref is not None else {}
    owners = _owners(ns, ks, T, comm.size, max(ns) if ref_serial else serial_max_n,
                     exclude=ref_rank)
    runs = []
    for n in ns:
        for k in ks:
            owner = owners[(n, k)]
            stepper = None
            if owner is None:
                stepper = ex.build(comm, n=n, k=k, T=T, overrides=overrides)
            elif owner == comm.rank:
                stepper = ex.build(MPI.COMM_SELF, n=n, k=k, T=T, overrides=overrides)
            runs.append(_CoarseRun(n, k, int(round(k / ref_k)), owner, stepper))
    check_family(ref, ref_n, runs, comm)  # the levels cover one domain and refine
    geometry = _cell_geometry(runs, comm)
    transfers = _Transfers(ref, ref_n, ns, geometry, comm)
    outbox = []
    for run in runs:
        run.connect(ref, *geometry[(run.n, run.k)], transfers, norms, ref_comm, ref_rank, comm,
                    outbox)
    transfers.check_coverage(runs, comm)  # a family that cannot be compared: refused now
    claim()
    num_steps = comm.bcast(ref.num_steps if comm.rank == 0 else None, root=0)
    report = Progress(f"{ex.id} converge", num_steps, comm, enabled=progress, interval=10.0)

    ref_wall = time.perf_counter()
    stats = solver_step(ref.initialize, "the reference, initial solve") if ref is not None else {}
    ref_wall = time.perf_counter() - ref_wall
    for run in runs:
        if run.mine:
            run.advance(initial=True)
    _check_states(ref, runs, comm, "t = 0")
    for run in runs:
        run.measure()
    step, measure_wall = 0, 0.0
    while step < num_steps:
        start = time.perf_counter()
        if ref is not None:
            stats = solver_step(ref.advance, f"the reference, step {step + 1}")
        ref_wall += time.perf_counter() - start
        step += 1
        due = [run for run in runs if step % run.ratio == 0]
        for run in due:  # serial cells first: no rank waits for the other inside a parallel one
            if run.mine and run.owner is not None:
                run.advance()
        for run in due:
            if run.owner is None:
                run.advance()
        _check_states(ref, due, comm, f"step {step} of the reference")
        start = time.perf_counter()
        for run in due:
            run.measure()
        measure_wall += time.perf_counter() - start
        if ref is not None:
            report(step, ref.t, stats, ref.scalars)
    MPI.Request.Waitall([req for req, _ in outbox])
    cell_wall = comm.allreduce(np.array([r.wall if r.mine and (r.owner is not None or
                                                               comm.rank == 0) else 0.0
                                         for r in runs]), op=MPI.SUM)
    for run, wall in zip(runs, cell_wall):
        run.wall = float(wall)

    components = comm.bcast([(name, None, norm) for name, _, norm in ref.error_components]
                            if comm.rank == 0 else None, root=0)
    if ref_serial:  # the errors were computed on rank 0
        errors = comm.bcast([(r.err, r.err_T, r.err_parts) for r in runs]
                            if comm.rank == 0 else None, root=0)
        for r, (err, err_T, parts) in zip(runs, errors):
            r.err, r.err_T, r.err_parts = err, err_T, parts
    definition = _error_definition(components)
    rows = [{"n": r.n, "h": r.h, "k": r.k, "h_plus_k": r.h + r.k, "error": r.err,
             **{f"error_{name}_{norm}": r.err_parts[name] for name, _, norm in components},
             "error_at_T": r.err_T, "wall_time_s": r.wall} for r in runs]
    for r in rows:
        if not all(np.isfinite(v) for key, v in r.items() if key.startswith("error")):
            raise ConvergenceError(f"the error of the cell n = {r['n']}, k = {r['k']:g} is not "
                                   "finite: a run of the study gave numbers that cannot be right")
    rates = fitted_rates(rows, ns, ks)
    rates_T = fitted_rates(rows, ns, ks, key="error_at_T")
    summary = {"schema": SCHEMA, "status": "completed", **settings, "example": ex.id,
               "title": ex.title,
               "reading": ex.reading, "ref_n": ref_n, "ref_k": ref_k, "T": T, "n": ns, "k": ks,
               "error_definition": definition, "norm": _norm_statement(components),
               "comparison": transfers.comparison,
               "errors": rows, "rates": rates, "rates_at_T": rates_T,
               **({"rates_note": "a rate without a value (null) needs two or more levels that "
                                 "differ in it"}
                  if not all(np.isfinite(v) for v in (*rates.values(), *rates_T.values())
                             if isinstance(v, float)) else {}),
               "mpi_size": comm.size,
               "serial_cells": {"max_n": (max(ns) if ref_serial else serial_max_n)
                                if comm.size > 1 else None,
                                "rank_of_cell": [[r.n, r.k, r.owner] for r in runs]},
               "reference": {"wall_time_s": ref_wall, "ranks": 1 if ref_serial else comm.size,
                             "measurements_wall_time_s": measure_wall,
                             **({"mesh": ref.mesh_info(), "final": ref.scalars(),
                                 "iterations": ref.iteration_totals()} if ref is not None else {})},
               "parameters": ref.params.as_dict() if ref is not None else None,
               "assumptions": ex.assumptions,
               "wall_time_s": time.perf_counter() - wall_start,
               "environment": io.environment(comm)}
    def tables():
        if comm.rank == 0:
            write_tables(out, rows, ns, ks, rates, rates_T, ex.id, ref_n, ref_k, definition)
            label = ex.id + (f", {ex.reading} reading" if ex.readings else "")
            plot_convergence(out / "convergence.png", rows, rates, label, ref_n, ref_k,
                             definition, title=f"{ex.id} (model {ex.model_id})" if ex.own
                             else f"{label}: {ex.title}")
    io.collective(comm, out, "the tables and convergence.png", tables)  # OutputError: exit 4
    if comm.rank == 0:
        if progress:  # progress=False prints nothing
            print((out / "errors.md").read_text(), flush=True)
    io.collective(comm, out, "summary.json", io.write_json, out / "summary.json", summary, comm)
    return summary
