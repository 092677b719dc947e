"""What each command does: ``list``, ``run``, ``converge``, ``sweep`` (the arguments are
parsed by arguments.py, the PETSc options checked by petsc_options.py; exit statuses: the
package's ``cli``)."""
from __future__ import annotations

import os
import sys

from mpi4py import MPI

from damage_dolfinx.cli.arguments import _check_finite, _overrides, _parser
from damage_dolfinx.cli.petsc_options import _check_petsc_values, _petsc_options, _unused


def command(argv, comm, given):
    """Parse and run the command; returns 0 (exceptions: main)."""
    parser = _parser()
    args, extra = parser.parse_known_args(argv)
    given.update(_petsc_options(extra, parser, args.command))
    _check_finite(args)
    _check_petsc_values(given)
    _load_plugins()
    if args.command != "list":
        from damage_dolfinx.runtime.signals import keeping_sigint
        with keeping_sigint():  # gmsh itself only where a mesh needs it (geometries)
            import dolfinx.io  # noqa: F401
    from damage_dolfinx.catalogue import examples  # the catalogue's ids (runtime/cases.py)
    if args.command == "list":
        if comm.rank == 0:
            for ex in examples.catalogue().values():
                reading = f" (reading: {ex.reading})" if ex.readings else ""
                print(f"{ex.id:10s} [Section {ex.section}] {ex.title}{reading}")
        return 0
    if args.command == "run":
        from damage_dolfinx.runtime import runner
        runner.run(args.id, args.out, n=args.n, k=args.k, T=args.T, h=args.h,
                   overrides=_overrides(args.set, args.friction_solver, args.friction_law,
                                        args.reading, args),
                   mesh_file=args.mesh,
                   write_every=args.write_every, progress=not args.quiet,
                   figures=not args.no_figures, checkpoint_every=args.checkpoint_every,
                   checkpoint_seconds=args.checkpoint_seconds, restart=args.restart,
                   overwrite=args.overwrite, history_every=args.history_every)
    elif args.command == "sweep":
        status = _sweep(args)
        if status:
            return status
    elif args.command == "converge":
        from damage_dolfinx.studies import convergence
        convergence.study(args.id, args.out, ref_n=args.ref_n, ref_k=args.ref_k,
                          ns=args.n, ks=args.k, T=args.T,
                          overrides=_overrides(args.set, args.friction_solver,
                                               args.friction_law, args.reading, args),
                          progress=not args.quiet,
                          reference_ranks={"1": 1, "all": "all", None: None}[
                              args.reference_ranks],
                          restart=args.restart, overwrite=args.overwrite)
    unused = _unused(given, comm)
    if unused and comm.rank == 0:
        print(f"damage-dolfinx: warning: no solver of this {args.command} read the PETSc "
              f"option(s) {' '.join(unused)}: they had no effect", file=sys.stderr,
              flush=True)
    return 0


def _sweep(args):
    from damage_dolfinx.parameters import InputError
    from damage_dolfinx.studies.sweep import parse_values, sweep
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


def _load_plugins():
    """Import the modules named in DAMAGE_DOLFINX_PLUGINS (comma-separated): they may register
    models (damage_dolfinx.register_model), friction solvers or case sources before the run."""
    import importlib
    from damage_dolfinx.parameters import InputError
    for name in filter(None, (n.strip() for n in os.environ.get("DAMAGE_DOLFINX_PLUGINS",
                                                                  "").split(","))):
        try:
            importlib.import_module(name)
        except ImportError as exc:
            raise InputError(f"DAMAGE_DOLFINX_PLUGINS names {name!r}, which cannot be "
                             f"imported: {exc}") from None
        except SystemExit as exc:  # a plugin may not end the command (exit 0, no run)
            raise InputError(f"plugin {name!r} (DAMAGE_DOLFINX_PLUGINS) called "
                             f"sys.exit({exc.code!r}) while being imported: the plugin "
                             "failed") from None
        except KeyboardInterrupt:
            raise
        except BaseException as exc:  # noqa: BLE001 - the plugin's failure, one line
            text = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
            raise InputError(f"plugin {name!r} (DAMAGE_DOLFINX_PLUGINS) failed while being "
                             f"imported: {type(exc).__name__}"
                             + (f": {text}" if text else "")) from None
