"""Running problems: :func:`run` one problem into a run folder, :func:`converge` a problem
against a fine reference, :func:`gather` a field onto rank 0 (any number of ranks).

``petsc_options`` (all four calls): PETSc options of the package's solvers for this call only,
``{"mech_ksp_type": "cg", "damage_snes_monitor": None}`` (names with or without the dash,
values str/number/bool, None for a flag), checked as the command line checks its own: a name
outside the solver prefixes (``mech_``, ``damage_``, ``friction_``, ``uzawa_``, ``pd_``,
``stability_``) or a value PETSc refuses raises InputError before any work, an option no solver
read is warned about (UserWarning) at the end, and the options database is as before after the
call. A script's own command line: ``petsc_options=dd.petsc_options_from_argv()``."""
from __future__ import annotations

import os
from typing import Any, Callable, Iterator, Mapping, Optional, Sequence, Union

from mpi4py import MPI

from damage_dolfinx.core.errors import InputError
from damage_dolfinx.core.validation import DEFAULTS as _D
from damage_dolfinx.problem.problem import Problem  # (light: no DOLFINx, for the annotations)
from damage_dolfinx.runtime.step import CHECKPOINT_SECONDS
from damage_dolfinx.runtime.steps import Steps

#: what a run is given: a Problem, or the id of a catalogue or registered example
ProblemLike = Union["Problem", str]
PathLike = Union[str, "os.PathLike[str]"]
PetscOptions = Optional[Mapping[str, Any]]


def _named(problem):
    """A catalogue id needs the catalogue loaded (it registers its ids with the run machinery,
    which does not import it)."""
    if isinstance(problem, str):
        import damage_dolfinx.catalogue  # noqa: F401
    return problem


def _petsc(petsc_options, comm, what):
    from damage_dolfinx.problem.petsc_options import scoped
    return scoped(petsc_options, comm, what)


def run(problem: ProblemLike, out: PathLike, *, n: Optional[int] = None,
        k: Optional[float] = None, T: Optional[float] = None, restart: bool = _D["restart"],
        overwrite: bool = _D["overwrite"], checkpoint_every: Optional[int] = _D["checkpoint_every"],
        progress: bool = _D["progress"], figures: bool = _D["figures"],
        comm: MPI.Comm = MPI.COMM_WORLD,
        on_step: Optional[Callable[[Any], Any]] = None,
        petsc_options: PetscOptions = None, h: Optional[float] = None,
        overrides: Optional[Mapping[str, Any]] = None, mesh_file: Optional[PathLike] = None,
        write_every: Optional[int] = None, checkpoint_seconds: float = CHECKPOINT_SECONDS,
        history_every: Optional[int] = None) -> dict:
    """Run ``problem`` (a :class:`~damage_dolfinx.Problem`, or a catalogue id such as
    ``"2.2-ex1"``) and write its run folder ``out``; returns the summary (also in
    ``out/summary.json``).

    The folder receives what the command line writes for a catalogue example: ``summary.json``
    (status, parameters, final scalars, timings, environment), ``fields.xdmf`` (u, zeta, von
    Mises ... over time, for ParaView), ``history.csv`` (scalars per step), ``fields_final.npz``,
    the figures, and checkpoints. ``restart=True`` continues from the folder's checkpoint (a
    larger ``T`` continues a completed run); a folder that already holds a run is refused
    unless ``restart`` or ``overwrite``. SIGTERM/SIGINT stop the run at the end of a step with a
    checkpoint. Under ``mpirun`` every rank calls it; only rank 0 prints. ``n``, ``k``, ``T``
    override the problem's own. ``fields.xdmf`` is one time series from t = 0 to the last step
    whatever restarts happened; :func:`~damage_dolfinx.read_run` reads the folder back.
    ``on_step(step)``: called after the initial state and after every step with the
    :class:`~damage_dolfinx.runtime.step.Step` (see :func:`steps`); a true return value stops
    the run there (status "stopped", with its outputs and a checkpoint: ``restart`` continues).

    The command line's ``run`` calls this function with the same names: ``h`` (the element size
    of a gmsh mesh family), ``overrides`` (changes to the problem's data for this run, e.g.
    ``{"kappa": 2.0, "reading": "evidence"}``), ``mesh_file`` (a gmsh file replacing a
    catalogue example's mesh), ``write_every`` (fields every that many steps), ``history_every``
    (a history row every that many steps), ``checkpoint_every`` / ``checkpoint_seconds`` (a
    checkpoint every that many steps, else every that many seconds of wall time; 0: none).
    ``petsc_options``: PETSc options of this run's solvers (the module's docstring).

    Raises (all importable from ``damage_dolfinx``; damage_dolfinx.core.errors):

    * :class:`~damage_dolfinx.InputError`: bad input, refused before any work (one line; a
      folder holding a run without ``restart=True`` or ``overwrite=True``, a k above
      ``problem.k_max()``, an unknown boundary name, ...);
    * :class:`~damage_dolfinx.ConvergenceError`: a solver did not converge or a field became
      NaN/inf or left [zeta*, 1]; summary.json says "failed", the finished steps stay;
    * :class:`~damage_dolfinx.OutputError`: an output could not be written (full disk, I/O
      error); summary.json says "failed" where space allows;
    * :class:`~damage_dolfinx.RunInterrupted`: SIGTERM, SIGINT or SIGUSR1 stopped the run at the
      end of a step after a checkpoint (summary.json "interrupted"; ``restart=True`` goes on).
    """
    from damage_dolfinx.runtime.collective import outcome
    from damage_dolfinx.runtime.runner import run as _run
    from damage_dolfinx.core.validation import check_run, communicator
    with outcome(communicator("comm", comm)):
        checked = check_run(out, comm, n=n, k=k, T=T, restart=restart, overwrite=overwrite,
                            checkpoint_every=checkpoint_every, progress=progress,
                            figures=figures, on_step=on_step, h=h, overrides=overrides,
                            mesh_file=mesh_file, write_every=write_every,
                            checkpoint_seconds=checkpoint_seconds, history_every=history_every)
        checked.pop("comm", None)
        checked.pop("out", None)
        with _petsc(petsc_options, comm, "run"):
            return _run(_named(problem), out, comm=comm, **checked)


def steps(problem: ProblemLike, out: PathLike, *, n: Optional[int] = None,
          k: Optional[float] = None, T: Optional[float] = None, restart: bool = _D["restart"],
          overwrite: bool = _D["overwrite"],
          checkpoint_every: Optional[int] = _D["checkpoint_every"],
          progress: bool = _D["progress"], figures: bool = _D["figures"],
          comm: MPI.Comm = MPI.COMM_WORLD,
          petsc_options: PetscOptions = None, h: Optional[float] = None,
          overrides: Optional[Mapping[str, Any]] = None, mesh_file: Optional[PathLike] = None,
          write_every: Optional[int] = None, checkpoint_seconds: float = CHECKPOINT_SECONDS,
          history_every: Optional[int] = None) -> "Steps":
    """The run of :func:`run` (the same arguments, the same run folder), step by step::

        with dd.steps(problem, "results/mine") as run:
            for step in run:
                R = step.contact_resultant()       # int_{Gamma_C} p nu ds, every rank
                if R is not None and abs(R[1]) > 2.0:
                    break                          # the run stops here: status "stopped"

    Each ``step`` (:class:`~damage_dolfinx.runtime.step.Step`, after the initial state and
    after every step) has ``n``, ``t``, the model and its live Functions ``u``, ``zeta``, ``v``
    (None where the scheme has none), ``contact_pressure`` (UFL, None without normal contact),
    ``contact_resultant()`` and the ``summary`` so far. Leaving the loop early stops the run at
    that step with its outputs and a checkpoint (``restart=True`` continues it). Under MPI
    every rank iterates and must stop at the same step (decide from collective values, as
    ``contact_resultant()`` is).

    An exception raised by your loop body is recorded as a failure only in the ``with`` form:
    on leaving the ``with`` block the run is ended without any collective call, summary.json
    says "failed" with the error, and every rank raises the same exception (a rank that raised
    alone, under MPI, ends the job within seconds instead of leaving the others waiting). A
    plain ``for step in dd.steps(...)`` loop works too, but Python closes the run alike after a
    ``break`` and after an exception of the body (the run cannot tell them apart): both are
    recorded as "stopped" when every rank leaves the loop at the same step. Under MPI the ranks
    agree after every step whether their loops went on: a loop left on some ranks only (an
    exception there) ends the others with an error, summary.json "failed" (without the text of
    the exception, which only the ``with`` form sees). Bad input raises InputError here, before
    any work."""
    from damage_dolfinx.runtime.collective import outcome
    from damage_dolfinx.runtime.loop import Run
    from damage_dolfinx.core.validation import check_run, communicator
    with outcome(communicator("comm", comm)):
        checked = check_run(out, comm, n=n, k=k, T=T, restart=restart, overwrite=overwrite,
                            checkpoint_every=checkpoint_every, progress=progress,
                            figures=figures, h=h, overrides=overrides, mesh_file=mesh_file,
                            write_every=write_every, checkpoint_seconds=checkpoint_seconds,
                            history_every=history_every)
        checked.pop("comm", None)
        checked.pop("out", None)
        scope = _petsc(petsc_options, comm, "run")
        scope.__enter__()  # left when the steps end (_within)
        try:
            run = Run.prepare(_named(problem), out, comm=comm, **checked)
        except BaseException:
            scope._restore()
            raise
    return Steps(run, comm, within=lambda steps: _within(steps, scope))


def _within(steps: Iterator, scope) -> Iterator:
    """The steps with the run's PETSc options in force until they end: the unread ones are
    warned about when the run goes to its end (a loop left early, or an exception, only
    restores the options database: no collective call there)."""
    try:
        yield from steps
    except BaseException:
        scope._restore()
        raise
    scope.__exit__(None, None, None)


def converge(problem: ProblemLike, out: PathLike, *, n: Optional[Sequence[int]] = None,
             k: Optional[Sequence[float]] = None, ref_n: Optional[int] = None,
             ref_k: Optional[float] = None, T: Optional[float] = None,
             progress: bool = _D["progress"], restart: bool = _D["restart"],
             overwrite: bool = _D["overwrite"], comm: MPI.Comm = MPI.COMM_WORLD,
             petsc_options: PetscOptions = None, overrides: Optional[Mapping[str, Any]] = None,
             reference_ranks: Union[int, str, None] = None) -> dict:
    """Errors of ``problem`` on the mesh levels ``n`` and time steps ``k`` against a reference
    run at (``ref_n``, ``ref_k``), with fitted rates; writes ``out/convergence.json``, tables
    and a plot, and returns the summary. The problem's mesh must be a family ``(comm, n) ->
    mesh``, the coarse levels below ``ref_n``, every k a multiple of ``ref_k``. Nested
    structured meshes (:func:`damage_dolfinx.geometries.rectangle.rectangle`; every n divides
    ``ref_n``) are transferred to the reference mesh exactly; any other family (a gmsh family,
    e.g. :func:`damage_dolfinx.geometries.plate_with_hole.plate_with_hole_family`) by exact
    point evaluation of the coarse fields at the reference mesh's nodes (P1) and cell midpoints
    (DG0); a family whose meshes do not cover the same domain is refused before any step.
    The summary states the norm (``norm``, ``error_definition``) and the comparison
    (``comparison``). ``progress=False`` prints nothing. ``restart=True`` on a folder
    holding a study: nothing to do when it completed with these settings, else it runs again
    (studies keep no checkpoints); a study whose settings or run fingerprint at any level (mesh,
    loads, law, ... as a run's restart checks) differ is refused, naming what changed.
    A folder that holds a study is refused unless ``restart`` or ``overwrite`` (the defaults
    of every entry, the command line's included: core.validation.DEFAULTS). ``petsc_options``: PETSc options of
    every run of the study (the module's docstring). ``n``, ``k``, ``ref_n``, ``ref_k`` left
    None take a catalogue example's default study (a problem of your own has none: give them).
    ``overrides``: changes to the problem's data, as for :func:`run`; ``reference_ranks``: 1
    (the reference serially, the coarse cells on the other ranks) or "all" (None: the
    example's default, else 1). The command line's ``converge`` calls this function."""
    from damage_dolfinx.runtime.collective import outcome
    from damage_dolfinx.studies.convergence import study
    from damage_dolfinx.core.validation import arguments, check_converge, communicator
    with outcome(communicator("comm", comm)):
        n, k, ref_n, ref_k, T, restart, overwrite = check_converge(
            n, k, ref_n, ref_k, T, restart, overwrite, progress, out, comm)
        checked = arguments(overrides=overrides, reference_ranks=reference_ranks)
        overrides, reference_ranks = checked["overrides"], checked["reference_ranks"]
        with _petsc(petsc_options, comm, "convergence study"):
            return study(_named(problem), out, ref_n=ref_n, ref_k=ref_k, ns=n, ks=k, T=T,
                         progress=progress, comm=comm, restart=restart, overwrite=overwrite,
                         overrides=overrides, reference_ranks=reference_ranks)


def gather(function: Any) -> "Optional[tuple[Any, Any]]":
    """``(coords, values)`` of a P1 or DG0 ``dolfinx.fem.Function`` on rank 0, all ranks'
    owned dofs in a rank-independent order (sorted by coordinates), so that a serial run and a
    parallel one compare entry by entry; ``None`` on the other ranks (collective). Anything
    else, a sub-function ``u.sub(i)`` among them (gather ``u.sub(i).collapse()``), is refused."""
    from damage_dolfinx.runtime.io import gather_dof_field
    V = getattr(function, "function_space", None)
    if V is None or not hasattr(function, "x") or not hasattr(V, "tabulate_dof_coordinates"):
        raise InputError(f"gather takes a dolfinx.fem.Function, got {type(function).__name__}")
    component = getattr(V, "component", None)  # a subspace's place in its parent
    if not (callable(component) and len(component()) > 0):
        try:
            return gather_dof_field(function)
        except RuntimeError as exc:  # DOLFINx: no dof coordinates of a subspace (every rank)
            if "subspace" not in str(exc):
                raise
    raise InputError("gather takes a whole Function, not a sub-function u.sub(i): gather "
                     "u.sub(i).collapse()")


def sweep(problem: ProblemLike, out: PathLike, grid: Mapping[str, Sequence[Any]], *,
          n: Optional[int] = None, k: Optional[float] = None, T: Optional[float] = None,
          restart: bool = False, max_points: Optional[int] = None, plot: str = "zeta_min",
          figures: bool = True, progress: bool = True, ranks_per_point: Optional[int] = None,
          point: Optional[int] = None, comm: MPI.Comm = MPI.COMM_WORLD,
          petsc_options: PetscOptions = None) -> dict:
    from damage_dolfinx.runtime.collective import outcome
    from damage_dolfinx.studies.sweep import sweep as _sweep
    from damage_dolfinx.core.validation import communicator
    with outcome(communicator("comm", comm)):
        scope = _petsc(petsc_options, comm, "sweep")
    with scope:
        return _sweep(_named(problem), out, grid, n=n, k=k, T=T, restart=restart,
                      max_points=max_points, plot=plot, figures=figures, progress=progress,
                      ranks_per_point=ranks_per_point, point=point, comm=comm)


def _sweep_doc():
    """studies.sweep's docstring and this call's petsc_options, both without indentation
    (Python 3.13 and later strip it from docstrings themselves: joined as they come, the two
    would be indented differently there)."""
    import inspect
    from damage_dolfinx.studies.sweep import sweep as _sweep  # light: no DOLFINx import
    return inspect.cleandoc(_sweep.__doc__) + (
        "\n\n``petsc_options``: PETSc options of every point's run (this module's docstring).")


sweep.__doc__ = _sweep_doc()
