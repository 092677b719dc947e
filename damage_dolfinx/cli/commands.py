"""What each command does: ``list``, ``run``, ``converge``, ``sweep`` (the arguments are
parsed by arguments.py, the PETSc options checked by petsc_options.py; exit statuses: the
package's ``cli``)."""
from __future__ import annotations

import os
import sys

from mpi4py import MPI

from damage_dolfinx.cli.arguments import _overrides, _parser
from damage_dolfinx.problem.petsc_options import _check_petsc_values, _petsc_options, _unused


def command(argv, comm, given):
    """Parse and run the command; returns 0 (exceptions: main)."""
    import logging
    argv = _help_or_mesh_size(sys.argv[1:] if argv is None else list(argv))
    parser = _parser()
    args, extra = parser.parse_known_args(argv)
    given.update(_petsc_options(extra, parser, args.command))
    _check_petsc_values(given)
    handler = _logging(args.log_level, comm)
    try:
        return _command(args, comm, given)
    finally:
        logging.getLogger("damage_dolfinx").removeHandler(handler)


def _help_or_mesh_size(argv):
    """``-h`` asks for help, except ``-h NUMBER``: the mesh size misspelt (``--h``)."""
    from damage_dolfinx.core.parameters import InputError
    for i, tok in enumerate(argv):
        if tok == "-h" and i + 1 < len(argv):
            try:
                float(argv[i + 1])
            except ValueError:
                continue
            raise InputError("unknown option -h: not a PETSc option of this program's solvers "
                             "(-h alone is the help); did you mean --h?")
    return argv


def _logging(level, comm):
    """The command's handler of the package's logger (stderr, rank 0; ``--log-level``); the
    root logger is left alone."""
    import logging
    logger = logging.getLogger("damage_dolfinx")
    handler = logging.StreamHandler(sys.stderr) if comm.rank == 0 else logging.NullHandler()
    handler.setFormatter(logging.Formatter("damage-dolfinx: %(levelname)s: %(message)s"))
    logger.addHandler(handler)
    logger.setLevel(getattr(logging, level.upper()))
    return handler


def _command(args, comm, given):
    from damage_dolfinx.cli import plugins
    plugins.load(args.plugin)
    if args.command != "list":
        from damage_dolfinx.runtime.signals import keeping_sigint
        with keeping_sigint():  # gmsh itself only where a mesh needs it (geometries)
            import dolfinx.io  # noqa: F401
    from damage_dolfinx.catalogue import examples  # the catalogue's ids (runtime/cases.py)
    if args.command == "list":
        if comm.rank == 0:
            from damage_dolfinx.runtime import cases
            for ex in examples.catalogue().values():
                reading = f" (reading: {ex.reading})" if ex.readings else ""
                print(f"{ex.id:10s} [Section {ex.section}] {ex.title}{reading}")
            for name, title in cases.registered().items():
                print(f"{name:10s} [registered] {title}")
        return 0
    if args.command == "show":
        from damage_dolfinx.cli.show import show
        text = show(args.id, _overrides(args.set, reading=args.reading))
        if comm.rank == 0:
            print(text, flush=True)
        return 0
    # every command is a client of the public API: the same entry points and checks a script
    # meets (damage_dolfinx.api.workflow; core.validation checks each argument by its name)
    from damage_dolfinx.api import workflow
    if args.command == "run":
        workflow.run(args.id, args.out, n=args.n, k=args.k, T=args.T, h=args.h,
                     overrides=_overrides(args.set, args.friction_solver, args.friction_law,
                                          args.reading, args),
                     mesh_file=args.mesh,
                     write_every=args.write_every, progress=not args.quiet,
                     figures=not args.no_figures, checkpoint_every=args.checkpoint_every,
                     checkpoint_seconds=args.checkpoint_seconds, restart=args.restart,
                     overwrite=args.overwrite, history_every=args.history_every, comm=comm)
    elif args.command == "sweep":
        status = _sweep(args)
        if status:
            return status
    elif args.command == "converge":
        workflow.converge(args.id, args.out, ref_n=args.ref_n, ref_k=args.ref_k,
                          n=args.n, k=args.k, T=args.T,
                          overrides=_overrides(args.set, args.friction_solver,
                                               args.friction_law, args.reading, args),
                          progress=not args.quiet,
                          reference_ranks={"1": 1, "all": "all", None: None}[
                              args.reference_ranks],
                          restart=args.restart, overwrite=args.overwrite, comm=comm)
    unused = _unused(given, comm)
    if unused and comm.rank == 0:
        print(f"damage-dolfinx: warning: no solver of this {args.command} read the PETSc "
              f"option(s) {' '.join(unused)}: they had no effect", file=sys.stderr,
              flush=True)
    return 0


def _sweep(args):
    from damage_dolfinx.api.workflow import sweep
    from damage_dolfinx.core.parameters import InputError
    from damage_dolfinx.studies.sweep import parse_values
    if not args.set:
        raise InputError("sweep needs at least one --set NAME=V1,V2,...")
    grid = {}
    for pair in args.set:
        if "=" not in pair:
            raise InputError(f"--set expects NAME=V1,V2,..., got {pair!r}")
        name, values = (part.strip() for part in pair.split("=", 1))
        if not name:
            raise InputError(f"--set {pair!r}: no parameter name")
        if name in grid:
            raise InputError(f"--set {name}: the parameter is given twice")
        grid[name] = parse_values(values, name) if values else []
    summary = sweep(args.id, args.out, grid, n=args.n, k=args.k, T=args.T,
                    restart=args.restart, max_points=args.max_points, plot=args.plot,
                    figures=not args.no_figures, progress=not args.quiet,
                    ranks_per_point=args.ranks_per_point, point=args.point)
    # a point failed: the sweep did not succeed (a job of one point: that point failed)
    failed = summary["failed_in_this_call"] if args.point is not None else summary["failed"]
    if failed:
        first = failed[0]
        why = summary.get("errors", {}).get(str(first)) or "see its summary.json"
        if MPI.COMM_WORLD.rank == 0:
            print(f"damage-dolfinx: failed: {len(failed)} of {summary['points']} "
                  f"points failed (point_{first}: {why})", file=sys.stderr, flush=True)
        return 3
    return 0
