"""Command line: ``damage-dolfinx list | run ID | converge ID`` (works unchanged under mpirun).

Options the parser does not know (``-mech_ksp_type cg``, ``-damage_snes_monitor``) go to the
PETSc options database. User errors print one line on rank 0 and exit with status 2; a solver
that does not converge exits with status 3 after writing what was finished; an output error
(disk full, I/O error, output folder deleted) exits with status 4; SIGTERM, SIGINT or SIGUSR1
stop a run at the end of the current step with a checkpoint, exit status 128 + signal number
(143, 130, 138).
"""
from __future__ import annotations

import argparse
import os
import sys

from mpi4py import MPI


def _parser():
    p = argparse.ArgumentParser(prog="damage-dolfinx", allow_abbrev=False,
                                description="Damage models of Campo (2007) with DOLFINx.")
    sub = p.add_subparsers(dest="command", required=True)
    sub.add_parser("list", help="list the example ids")

    def common(sp):
        sp.add_argument("id", help="example id, e.g. 2.1-ex1 (see `list`)")
        sp.add_argument("--T", type=float, help="final time")
        sp.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        help="override a model parameter, e.g. --set kappa=0.01 (repeatable)")
        sp.add_argument("--out", required=True, help="output folder")
        sp.add_argument("--quiet", action="store_true", help="no progress lines")
        sp.add_argument("--allow-unstable", action="store_true",
                        help="run a time step above the scheme's stability limit k_max (a "
                             "warning instead of a refusal), to study instability on purpose")
        sp.add_argument("--allow-long", action="store_true",
                        help="allow more than 10^7 time steps")
        sp.add_argument("--friction-solver", choices=("newton", "uzawa", "penalty-duality"),
                        help="Tresca solver of Sections 2.2/2.4/3.2 (same as --set friction_solver=...)")
        sp.add_argument("--friction-law", choices=("tresca", "coulomb"),
                        help="Section 2.4: Tresca (P1) or simplified Coulomb (P2) "
                             "(same as --set friction_law=...)")
        sp.add_argument("--reading", choices=("literal", "evidence"),
                        help="thesis data read literally or as the evidence reading ("
                             "default: the example's default_reading, see `list`)")

    run = sub.add_parser("run", help="run one example", allow_abbrev=False)
    common(run)
    run.add_argument("--n", type=int, help="cells per side (structured meshes)")
    run.add_argument("--h", type=float, help="element size (gmsh meshes)")
    run.add_argument("--k", type=float, help="time step")
    run.add_argument("--mesh", help="gmsh .msh file replacing the built-in geometry")
    run.add_argument("--write-every", type=int, help="XDMF output every N steps (default N/20)")
    run.add_argument("--history-every", type=int, metavar="N",
                     help="a history.csv row every N steps (default: the example's, mostly 1)")
    run.add_argument("--no-figures", action="store_true", help="skip the PNG figures")
    run.add_argument("--checkpoint-every", type=int, metavar="STEPS",
                     help="write a checkpoint every STEPS steps (default: every "
                          "--checkpoint-seconds of wall time)")
    run.add_argument("--checkpoint-seconds", type=float, default=120.0,
                     help="wall-time interval between checkpoints (0: none; default 120)")
    run.add_argument("--restart", action="store_true",
                     help="resume from the checkpoint in --out (any number of MPI ranks)")
    run.add_argument("--overwrite", action="store_true",
                     help="replace a run already in --out (without it such a folder is refused)")

    conv = sub.add_parser("converge", help="convergence study against a fine reference",
                          allow_abbrev=False)
    common(conv)
    conv.add_argument("--ref-n", type=int, help="reference mesh (cells per side)")
    conv.add_argument("--ref-k", type=float, help="reference time step")
    conv.add_argument("--n", type=int, nargs="+", help="coarse meshes")
    conv.add_argument("--k", type=float, nargs="+", help="coarse time steps")
    conv.add_argument("--reference-ranks", choices=("1", "all"),
                      help="the reference on rank 0 alone, every cell serially on the other "
                           "ranks (1), or the reference and the cells n > 64 on all ranks "
                           "(all); default: the example's choice (convergence.py)")
    return p


def _petsc_options(tokens):
    """Put '-name [value]' tokens into the PETSc options database; returns unparsed leftovers."""
    from petsc4py import PETSc
    opts, leftovers, i = PETSc.Options(), [], 0
    while i < len(tokens):
        tok = tokens[i]
        if tok.startswith("-") and not tok.startswith("--") and len(tok) > 1:
            value = tokens[i + 1] if i + 1 < len(tokens) and not _is_option(tokens[i + 1]) else None
            opts[tok[1:]] = value if value is not None else ""
            i += 2 if value is not None else 1
        else:
            leftovers.append(tok)
            i += 1
    return leftovers


def _is_option(tok):
    if not tok.startswith("-"):
        return False
    try:
        float(tok)
        return False
    except ValueError:
        return True


def _overrides(pairs, friction_solver=None, friction_law=None, reading=None, args=None):
    from damage_dolfinx.parameters import InputError
    out = {} if friction_solver is None else {"friction_solver": friction_solver}
    if args is not None and args.allow_unstable:
        out["stability_check"] = "warn"
    if args is not None and args.allow_long:
        out["allow_long"] = True
    if friction_law is not None:
        out["friction_law"] = friction_law
    if reading is not None:
        out["reading"] = reading
    for pair in pairs:
        if "=" not in pair:
            raise InputError(f"--set expects NAME=VALUE, got {pair!r}")
        name, value = pair.split("=", 1)
        out[name.strip()] = value.strip()
    return out


def _check_finite(args):
    """Every number on the command line is finite (argparse's float() accepts 'inf' and 'nan')."""
    import math
    from damage_dolfinx.parameters import InputError
    for name, value in vars(args).items():
        for v in value if isinstance(value, list) else [value]:
            if isinstance(v, float) and not math.isfinite(v):
                raise InputError(f"--{name.replace('_', '-')} must be a finite number, got {v}")


def main(argv=None):
    comm = MPI.COMM_WORLD
    args, extra = _parser().parse_known_args(argv)
    from damage_dolfinx.parameters import InputError
    from damage_dolfinx.numerics.solvers import ConvergenceError
    from damage_dolfinx.runtime.io import OutputError
    from damage_dolfinx.runtime.runner import RunInterrupted
    try:
        leftovers = _petsc_options(extra)
        if leftovers:
            raise InputError(f"unrecognised arguments: {' '.join(leftovers)}")
        _check_finite(args)
        if args.command == "list":
            from damage_dolfinx.catalogue import examples
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
            return 0
        if args.command == "converge":
            from damage_dolfinx.studies import convergence
            convergence.study(args.id, args.out, ref_n=args.ref_n, ref_k=args.ref_k,
                              ns=args.n, ks=args.k, T=args.T,
                              overrides=_overrides(args.set, args.friction_solver,
                                                   args.friction_law, args.reading, args),
                              progress=not args.quiet,
                              reference_ranks={"1": 1, "all": "all", None: None}[
                                  args.reference_ranks])
            return 0
    except InputError as exc:
        if comm.rank == 0:
            print(f"damage-dolfinx: error: {exc}", file=sys.stderr, flush=True)
        return 2
    except ConvergenceError as exc:
        if comm.rank == 0:
            print(f"damage-dolfinx: solver failure: {exc}", file=sys.stderr, flush=True)
        return 3
    except OutputError as exc:
        if comm.rank == 0:
            print(f"damage-dolfinx: output error: {exc}", file=sys.stderr, flush=True)
        from damage_dolfinx.runtime.io import FAILED_HDF5_FILES
        if FAILED_HDF5_FILES:  # HDF5 would crash shutting down the failed file
            sys.stdout.flush()
            comm.Barrier()
            os._exit(4)
        return 4
    except RunInterrupted as exc:
        import signal
        from damage_dolfinx.runtime.runner import STOP_SIGNALS
        for s in STOP_SIGNALS:  # the request arriving twice must not kill us on the way out
            signal.signal(s, signal.SIG_IGN)
        if comm.rank == 0:
            print(f"damage-dolfinx: {exc}", file=sys.stderr, flush=True)
        return exc.exit_status
    return 1


if __name__ == "__main__":
    sys.exit(main())
