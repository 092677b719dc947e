"""Running problems: :func:`run` one problem into a run folder, :func:`converge` a problem
against a fine reference, :func:`gather` a field onto rank 0 (any number of ranks)."""
from __future__ import annotations

from mpi4py import MPI

from damage_dolfinx.validation import DEFAULTS as _D


def _named(problem):
    """A catalogue id needs the catalogue loaded (it registers its ids with the run machinery,
    which does not import it)."""
    if isinstance(problem, str):
        import damage_dolfinx.catalogue  # noqa: F401
    return problem


def run(problem, out, *, n=None, k=None, T=None, restart=_D["restart"],
        overwrite=_D["overwrite"], checkpoint_every=_D["checkpoint_every"],
        progress=_D["progress"], figures=_D["figures"], comm=MPI.COMM_WORLD,
        on_step=None) -> dict:
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
    :class:`~damage_dolfinx.runtime.runner.Step` (see :func:`steps`); a true return value stops
    the run there (status "stopped", with its outputs and a checkpoint: ``restart`` continues).

    Raises (all importable from ``damage_dolfinx``; damage_dolfinx.errors):

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
    from damage_dolfinx.validation import check_run, communicator
    with outcome(communicator("comm", comm)):
        checked = check_run(n, k, T, restart, overwrite, checkpoint_every, progress, figures, out,
                            comm, on_step)
        n, k, T, restart, overwrite = (checked[key] for key in ("n", "k", "T", "restart",
                                                                 "overwrite"))
        checkpoint_every, progress, figures = (checked[key] for key in (
            "checkpoint_every", "progress", "figures"))
        return _run(_named(problem), out, n=n, k=k, T=T, restart=restart, overwrite=overwrite,
                    checkpoint_every=checkpoint_every, progress=progress, figures=figures,
                    comm=comm, on_step=on_step)


def steps(problem, out, *, n=None, k=None, T=None, restart=_D["restart"],
          overwrite=_D["overwrite"], checkpoint_every=_D["checkpoint_every"],
          progress=_D["progress"], figures=_D["figures"], comm=MPI.COMM_WORLD):
    """The run of :func:`run` (the same arguments, the same run folder), step by step::

        with dd.steps(problem, "results/mine") as run:
            for step in run:
                R = step.contact_resultant()       # int_{Gamma_C} p nu ds, every rank
                if R is not None and abs(R[1]) > 2.0:
                    break                          # the run stops here: status "stopped"

    Each ``step`` (:class:`~damage_dolfinx.runtime.runner.Step`, after the initial state and
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
    from damage_dolfinx.runtime.steps import Steps
    from damage_dolfinx.validation import check_run, communicator
    with outcome(communicator("comm", comm)):
        checked = check_run(n, k, T, restart, overwrite, checkpoint_every, progress, figures,
                            out, comm)
        n, k, T, restart, overwrite, checkpoint_every, progress, figures = (
            checked[key] for key in ("n", "k", "T", "restart", "overwrite", "checkpoint_every",
                                     "progress", "figures"))
        run = Run.prepare(_named(problem), out, n=n, k=k, T=T, restart=restart,
                          overwrite=overwrite, checkpoint_every=checkpoint_every,
                          progress=progress, figures=figures, comm=comm)
    return Steps(run, comm)


def converge(problem, out, *, n, k, ref_n, ref_k, T=None, progress=_D["progress"],
             restart=_D["restart"], overwrite=_D["overwrite"], comm=MPI.COMM_WORLD) -> dict:
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
    of every entry, the command line's included: validation.DEFAULTS)."""
    from damage_dolfinx.runtime.collective import outcome
    from damage_dolfinx.studies.convergence import study
    from damage_dolfinx.validation import check_converge, communicator
    with outcome(communicator("comm", comm)):
        n, k, ref_n, ref_k, T, restart, overwrite = check_converge(
            n, k, ref_n, ref_k, T, restart, overwrite, progress, out, comm)
        return study(_named(problem), out, ref_n=ref_n, ref_k=ref_k, ns=n, ks=k, T=T,
                     progress=progress, comm=comm, restart=restart, overwrite=overwrite)


def gather(function):
    """``(coords, values)`` of a P1 or DG0 ``dolfinx.fem.Function`` on rank 0, all ranks'
    owned dofs in a rank-independent order (sorted by coordinates), so that a serial run and a
    parallel one compare entry by entry; ``None`` on the other ranks (collective)."""
    from damage_dolfinx.runtime.io import gather_dof_field
    return gather_dof_field(function)


def sweep(problem, out, grid, **kwargs) -> dict:
    from damage_dolfinx.studies.sweep import sweep as _sweep
    return _sweep(_named(problem), out, grid, **kwargs)


def _sweep_doc():
    from damage_dolfinx.studies.sweep import sweep as _sweep  # light: no DOLFINx import
    return _sweep.__doc__


sweep.__doc__ = _sweep_doc()
