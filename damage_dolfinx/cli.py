"""Command line: ``damage-dolfinx list | run ID | converge ID | sweep ID`` (works unchanged under
mpirun).

Single-dash options are PETSc options of the package's solvers (``-mech_ksp_type cg``,
``-damage_snes_monitor``; prefixes PETSC_PREFIXES): any other single-dash word is refused with
the double-dash option it resembles, a value PETSc refuses is refused before any work, and an
option no solver read is named in a warning at the end. User errors print one line on rank 0
and exit with status 2; a solver
that does not converge or fails, or a state that is not finite or leaves [zeta_star, 1], exits
with status 3 after writing what was finished (summary.json "failed"); an output error
(disk full, I/O error, output folder deleted) exits with status 4; SIGTERM, SIGINT or SIGUSR1
stop a run at the end of the current step with a checkpoint, exit status 128 + signal number
(143, 130, 138); a repeat of the signal within 5 s is ignored, a later one ends the process
at once (signals.StopSignals). Outside a run's time loop (set-up, a convergence study, a sweep
between points) SIGTERM and SIGINT stop the command with one line, the status recorded and the
same exit status. Any other exception (the user's own code) is one line, exit status 3. Under
MPI every rank ends with the same status, also when only one rank failed
(runtime/collective.py).
"""
from __future__ import annotations

import argparse
import os
import sys

import numpy as np
from mpi4py import MPI


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (InputError, exit status 2) and only the long form of
    help: ``-h`` is the mesh size misspelt (--h), not a request for help."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("add_help", False)
        super().__init__(*args, **kwargs)
        self.add_argument("--help", action="help", help="show this help and exit")

    def error(self, message):
        from damage_dolfinx.parameters import InputError
        raise InputError(message)


def _parser():
    p = _Parser(prog="damage-dolfinx", allow_abbrev=False,
                description="Damage models of Campo (2007) with DOLFINx.")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
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
                     help="replace a run already in --out: the files its manifest.json lists "
                          "(without it such a folder is refused)")

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
    conv.add_argument("--restart", action="store_true",
                      help="a study already in --out: nothing to do if it finished with these "
                           "settings, else it runs again (studies keep no checkpoints)")
    conv.add_argument("--overwrite", action="store_true",
                      help="replace a study already in --out: the files its manifest.json lists")
    _sweep_parser(sub)
    return p


def _sweep_parser(sub):
    """The ``sweep`` subcommand: one example or mesh over a grid of parameter values."""
    sw = sub.add_parser("sweep", help="run an example over a grid of parameter values",
                        allow_abbrev=False,
                        description="Run an example at every point of a parameter grid (the "
                                    "product of the --set lists), each point a run folder "
                                    "OUT/point_<i>, shared out among the MPI ranks; a sweep run "
                                    "again keeps its finished points. Writes OUT/points.json, "
                                    "OUT/sweep.csv (every point's final scalars) and "
                                    "OUT/sweep.png.")
    sw.add_argument("id", help="example id, e.g. 2.1-ex1 (see `list`)")
    sw.add_argument("--set", action="append", default=[], metavar="NAME=V1,V2,...",
                    help="a swept parameter and its values, e.g. --set kappa=0.01,0.1,1 "
                         "(repeatable; one value fixes the parameter)")
    sw.add_argument("--out", required=True, help="sweep folder")
    sw.add_argument("--n", type=int, help="cells per side (structured meshes), every point")
    sw.add_argument("--k", type=float, help="time step, every point")
    sw.add_argument("--T", type=float, help="final time, every point")
    sw.add_argument("--restart", action="store_true",
                    help="resume interrupted points from their checkpoints (without it they "
                         "rerun from the start); finished points are always kept")
    sw.add_argument("--max-points", type=int, metavar="N",
                    help="run at most N of the unfinished points, then stop")
    sw.add_argument("--plot", default="zeta_min", metavar="SCALAR",
                    help="final scalar drawn against the swept parameters (default zeta_min)")
    sw.add_argument("--no-figures", action="store_true", help="no PNG figures per point")
    sw.add_argument("--quiet", action="store_true", help="no progress lines")


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
                    figures=not args.no_figures, progress=not args.quiet)
    if summary.get("status") == "failed":  # a point failed: the sweep did not succeed
        first = summary["failed"][0]
        why = summary.get("errors", {}).get(str(first)) or "see its summary.json"
        if MPI.COMM_WORLD.rank == 0:
            print(f"damage-dolfinx: failed: {len(summary['failed'])} of {summary['points']} "
                  f"points failed (point_{first}: {why})", file=sys.stderr, flush=True)
        return 3
    return 0


#: prefixes of the package's PETSc solvers (an option -<prefix><name> reaches one of them)
PETSC_PREFIXES = ("mech_", "damage_", "friction_", "uzawa_", "pd_", "stability_")
#: PETSc options without a solver prefix that are accepted (diagnostics of the whole run)
PETSC_GLOBAL = ("log_view", "options_left", "options_view", "info", "malloc_dump",
                "memory_view", "log_trace")
#: the part of an option name after which the PETSc object's own options start
_OBJECT_PARTS = ("snes_", "ksp_", "pc_")


def _petsc_options(tokens, parser, command):
    """Check the tokens argparse did not know and put the PETSc options among them into the
    options database; returns {name: value} of those set. Raises InputError for a single-dash
    word that is no PETSc option of the package's solvers (suggesting the double-dash option),
    an unknown double-dash option and a stray word."""
    from petsc4py import PETSc
    from damage_dolfinx.parameters import InputError
    given, i = {}, 0
    while i < len(tokens):
        tok = tokens[i]
        value = tokens[i + 1] if i + 1 < len(tokens) and not _is_option(tokens[i + 1]) else None
        if tok.startswith("--"):
            raise InputError(f"unrecognised option {tok.split('=')[0]}"
                             f"{_suggestion(tok.split('=')[0], parser, command)}")
        if not tok.startswith("-") or len(tok) == 1 or not _is_option(tok):
            raise InputError(f"unrecognised argument {tok!r}")
        name = tok[1:]
        if not (name.startswith(PETSC_PREFIXES) or name in PETSC_GLOBAL):
            hint = _suggestion("--" + name, parser, command)
            raise InputError(f"unknown option {tok}: not a PETSc option of this program's "
                             f"solvers (prefixes {', '.join(PETSC_PREFIXES)}){hint}")
        given[name] = value if value is not None else ""
        i += 2 if value is not None else 1
    opts = PETSc.Options()
    for name, value in given.items():
        opts[name] = value
    return given


def _suggestion(option, parser, command) -> str:
    """'; did you mean --x?' for the closest option of the command, or ''."""
    import difflib
    sub = _subparser(parser, command)
    known = [o for a in (sub or parser)._actions for o in a.option_strings if o.startswith("--")]
    if option in known:
        return f"; did you mean {option}?"
    close = difflib.get_close_matches(option, known, n=1, cutoff=0.6)
    return f"; did you mean {close[0]}?" if close else ""


def _subparser(parser, command):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return action.choices.get(command)
    return None


def _check_petsc_values(given):
    """Every PETSc option given is applied to a throwaway SNES (with its KSP and PC) of its
    prefix, so that a value PETSc refuses (-mech_ksp_type nonsense) is refused now, before any
    work, with one line; the options are then set anew, so that whether a solver of the run
    reads them (``_unused``) is not confused by this check."""
    from petsc4py import PETSc
    from damage_dolfinx.parameters import InputError
    prefixes = set()
    for name in given:
        cut = [name.find(part) for part in _OBJECT_PARTS if name.find(part) > 0]
        if cut and name.startswith(PETSC_PREFIXES):
            prefixes.add(name[:min(cut)])
    for prefix in sorted(prefixes):
        snes = PETSc.SNES().create(PETSc.COMM_SELF)
        try:
            snes.setOptionsPrefix(prefix)
            snes.setFromOptions()
        except PETSc.Error as exc:
            lines = [line.strip().lstrip("[0123456789] ") for line in str(exc).splitlines()]
            reason = next((line for line in reversed(lines) if line and "() at " not in line),
                          f"error code {exc.ierr}")
            options = " ".join(f"-{n} {v}".strip() for n, v in given.items()
                               if n.startswith(prefix))
            raise InputError(f"PETSc refuses the options {options}: {reason}") from None
        finally:
            snes.destroy()
    opts = PETSc.Options()
    for name, value in given.items():
        opts.delValue(name)
        opts[name] = value


def _unused(given, comm):
    """The PETSc options given that no solver of the run read (all ranks agree), or []."""
    from damage_dolfinx import compat
    names = [n for n in given if n not in PETSC_GLOBAL]
    used = [compat.petsc_option_used(n) for n in names]
    if any(u is None for u in used):
        return []
    used = np.array(used, dtype=np.int32)
    if names:  # element-wise (the pickling allreduce compares whole arrays: two or more fail)
        comm.Allreduce(MPI.IN_PLACE, used, op=MPI.MAX)
    return [f"-{n}" for n, u in zip(names, used) if not u]


def _forget(given):
    """Remove the options of this command, and the solvers' defaults, from the PETSc database
    (a later command in the same process, e.g. the tests, starts clean)."""
    from petsc4py import PETSc
    opts = PETSc.Options()
    for name in given:
        opts.delValue(name)
    if "dolfinx" in sys.modules:  # a solver may have run
        from damage_dolfinx.numerics import solvers
        for name in list(solvers._CODE_DEFAULTS):
            opts.delValue(name)
        solvers._CODE_DEFAULTS.clear()


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


def main(argv=None):
    """The command; every rank returns the same exit status (runtime/collective.py: an
    exception on one rank only becomes one decided outcome, or ends the job)."""
    import signal
    from damage_dolfinx.runtime.signals import stop_outside_runs
    comm = MPI.COMM_WORLD
    given = {}
    before = {}
    try:
        for s in (signal.SIGTERM, signal.SIGINT):  # the run's loop has its own (StopSignals)
            before[s] = signal.signal(s, stop_outside_runs)
    except ValueError:  # not the main thread
        pass
    try:
        return _main(argv, comm, given)
    finally:
        for s, handler in before.items():
            if signal.getsignal(s) is stop_outside_runs:  # (an interruption leaves SIG_IGN)
                signal.signal(s, handler)


def _main(argv, comm, given):
    from damage_dolfinx.runtime import collective
    from damage_dolfinx.runtime.io import OutputError
    from damage_dolfinx.runtime.signals import RunInterrupted
    try:
        with collective.outcome(comm):
            try:
                return _command(argv, comm, given)
            finally:
                _forget(given)
    except OutputError as exc:
        _say(comm, collective.line(exc))
        from damage_dolfinx.runtime.io import FAILED_HDF5_FILES
        if FAILED_HDF5_FILES:  # HDF5 would crash shutting down the failed file
            sys.stdout.flush()
            comm.Barrier()
            os._exit(4)
        return 4
    except (RunInterrupted, KeyboardInterrupt, collective.RankFailure) as exc:
        import signal
        from damage_dolfinx.runtime.signals import STOP_SIGNALS
        if not isinstance(exc, collective.RankFailure) or exc.kind == "":
            for s in STOP_SIGNALS:  # the request arriving twice must not kill us on the way out
                signal.signal(s, signal.SIG_IGN)
        _say(comm, collective.line(exc))
        return collective.classify(exc)[0]
    except Exception as exc:  # noqa: BLE001 - input, solver, user code: one line, its status
        _say(comm, collective.line(exc))
        return collective.classify(exc)[0]


def _say(comm, text):
    if comm.rank == 0:
        from damage_dolfinx.errors import for_command_line
        print(for_command_line(text), file=sys.stderr, flush=True)


def _command(argv, comm, given):
    """Parse and run the command; returns 0 (exceptions: main)."""
    parser = _parser()
    args, extra = parser.parse_known_args(argv)
    given.update(_petsc_options(extra, parser, args.command))
    _check_finite(args)
    _check_petsc_values(given)
    _load_plugins()
    if args.command != "list":
        from damage_dolfinx.runtime.signals import import_gmsh_keeping_sigint
        import_gmsh_keeping_sigint()
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


if __name__ == "__main__":
    sys.exit(main())
