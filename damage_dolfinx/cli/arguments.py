"""The command line's arguments: the parser of every subcommand (one-line errors, exit status
2) and the reading of ``--set`` and of the numbers given."""
from __future__ import annotations

import argparse


class _Formatter(argparse.RawDescriptionHelpFormatter):
    """Help with every default shown (argparse's ArgumentDefaultsHelpFormatter, without the
    "(default: None)" of an option whose default is the example's own: its help says so)."""

    def _get_help_string(self, action):
        text = action.help or ""
        if "%(default)" in text or action.default in (None, False, [], argparse.SUPPRESS):
            return text
        if action.option_strings or action.nargs in (argparse.OPTIONAL, argparse.ZERO_OR_MORE):
            text += " (default: %(default)s)"
        return text


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (InputError, exit status 2), the defaults in the help,
    and ``-h``/``--help`` (``-h`` followed by a number is the mesh size misspelt, refused by
    the command: did you mean --h?)."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("add_help", False)
        kwargs.setdefault("formatter_class", _Formatter)
        super().__init__(*args, **kwargs)
        self.add_argument("-h", "--help", action="help", help="show this help and exit")

    def error(self, message):
        from damage_dolfinx.core.parameters import InputError
        raise InputError(message)


#: the logging levels of --log-level
LOG_LEVELS = ("debug", "info", "warning", "error")

_EPILOG = """\
Single-dash options are PETSc options of the solvers (-mech_ksp_type cg, -damage_snes_monitor;
prefixes mech_ damage_ friction_ uzawa_ pd_ stability_). Plugins (--plugin, or the
comma-separated DAMAGE_DOLFINX_PLUGINS): a module on the path or in the current folder, or a
file (./my_model.py), imported before the command; it may register models and examples.
Exit status: 0 done, 2 bad input, 3 solver failure, 4 output error, 128+N signal N."""


def _add_session(sp):
    """Options of every subcommand: plugins and logging."""
    sp.add_argument("--plugin", action="append", default=[], metavar="MODULE|FILE.py",
                    help="import a plugin before the command (repeatable; also "
                         "DAMAGE_DOLFINX_PLUGINS): a module on the path or in the current "
                         "folder, or a file path")
    sp.add_argument("--log-level", choices=LOG_LEVELS, default="warning",
                    help="messages of the package's logger (damage_dolfinx) shown on stderr")


def _parser():
    from damage_dolfinx.core.version import __version__
    p = _Parser(prog="damage-dolfinx", allow_abbrev=False, epilog=_EPILOG,
                description="Damage models of Campo (2007) with DOLFINx: run an example of "
                            "the thesis catalogue\n(or a model or example a plugin registers), "
                            "study its convergence, sweep its parameters.\n"
                            "`damage-dolfinx COMMAND -h` shows a command's options.")
    p.add_argument("--version", action="version", version=f"damage-dolfinx {__version__}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser,
                           metavar="{list,show,run,converge,sweep}")
    _add_session(sub.add_parser("list", help="list the example ids (and the models a plugin "
                                             "registers)", allow_abbrev=False))
    show = sub.add_parser("show", help="an example's data before running it: n, k, T, mesh, "
                                       "reading, parameters", allow_abbrev=False)
    show.add_argument("id", help="example id, e.g. 2.1-ex1 (see `list`), or the id of a model "
                                 "or example a plugin registers")
    show.add_argument("--reading", choices=("literal", "evidence"),
                      help="the data under this reading (default: the example's)")
    show.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                      help="the data with this parameter overridden (repeatable)")
    _add_session(show)

    def common(sp):
        sp.add_argument("id", help="example id, e.g. 2.1-ex1 (see `list`), or the id of a "
                                   "model or example a plugin registers")
        sp.add_argument("--T", type=float, help="final time (default: the example's, see "
                                                "`show ID`)")
        sp.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        help="override a model parameter, e.g. --set kappa=0.01 (repeatable)")
        sp.add_argument("--out", required=True, help="output folder")
        sp.add_argument("--quiet", action="store_true", help="no progress lines")
        _add_session(sp)
        sp.add_argument("--allow-unstable", action="store_true",
                        help="run a time step above the scheme's stability limit k_max (a "
                             "warning instead of a refusal), to study instability on purpose")
        sp.add_argument("--allow-long", action="store_true",
                        help="allow more than 10^7 time steps")
        sp.add_argument("--friction-solver", choices=("newton", "uzawa", "penalty-duality"),
                        help="Tresca solver of Sections 2.2/2.4/3.2 "
                             "(same as --set friction_solver=...)")
        sp.add_argument("--friction-law", choices=("tresca", "coulomb"),
                        help="Section 2.4: Tresca (P1) or simplified Coulomb (P2) "
                             "(same as --set friction_law=...)")
        sp.add_argument("--reading", choices=("literal", "evidence"),
                        help="thesis data read literally or as the evidence reading ("
                             "default: the example's default_reading, see `list`)")

    run = sub.add_parser("run", help="run one example", allow_abbrev=False)
    common(run)
    run.add_argument("--n", type=int, help="cells per side (structured meshes; default: the "
                                           "example's, see `show ID`)")
    run.add_argument("--h", type=float, help="element size (gmsh meshes; default: the "
                                             "example's)")
    run.add_argument("--k", type=float, help="time step (default: the example's, within its "
                                             "stability limit)")
    run.add_argument("--mesh", help="gmsh .msh file replacing the built-in geometry")
    run.add_argument("--write-every", type=int, help="XDMF output every N steps (default N/20)")
    run.add_argument("--history-every", type=int, metavar="N",
                     help="a history.csv row every N steps (default: the example's, mostly 1)")
    run.add_argument("--no-figures", action="store_true", help="skip the PNG figures")
    run.add_argument("--checkpoint-every", type=int, metavar="STEPS",
                     help="write a checkpoint every STEPS steps (default: every "
                          "--checkpoint-seconds of wall time)")
    run.add_argument("--checkpoint-seconds", type=float, default=120.0,
                     help="wall-time interval between checkpoints (0: none)")
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
    from damage_dolfinx.core.validation import DEFAULTS  # the API's defaults, in one place
    for sp in (run, conv):
        sp.set_defaults(restart=DEFAULTS["restart"], overwrite=DEFAULTS["overwrite"],
                        checkpoint_every=DEFAULTS["checkpoint_every"])
    return p


def _sweep_parser(sub):
    """The ``sweep`` subcommand: one example or mesh over a grid of parameter values."""
    sw = sub.add_parser("sweep", help="run an example over a grid of parameter values",
                        allow_abbrev=False,
                        description="Run an example at every point of a parameter grid (the "
                                    "product of the --set lists), each point a run folder "
                                    "OUT/point_<i>, shared out among the MPI ranks; a sweep run "
                                    "again keeps its finished points. Writes OUT/points.json, "
                                    "OUT/sweep.csv (every point's final scalars, one row per "
                                    "point in the grid's order: point i is row i, the last "
                                    "--set varying fastest) and OUT/sweep.png. "
                                    "--ranks-per-point R runs each point in parallel on a "
                                    "group of R ranks; --point I runs point I alone (a job of "
                                    "a job array: several jobs may write OUT at once).")
    sw.add_argument("id", help="example id, e.g. 2.1-ex1 (see `list`), or the id of a model or "
                               "example a plugin registers")
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
    sw.add_argument("--ranks-per-point", type=int, metavar="R",
                    help="run each point in parallel on a group of R ranks, the groups "
                         "sharing out the points (R divides the number of ranks; default 1)")
    sw.add_argument("--point", type=int, metavar="I",
                    help="run point I alone (0-based, row I of sweep.csv), on all ranks: one "
                         "job of a job array (e.g. --point $SLURM_ARRAY_TASK_ID); a completed "
                         "point is not run again")
    sw.add_argument("--plot", default="zeta_min", metavar="SCALAR",
                    help="final scalar drawn against the swept parameters")
    sw.add_argument("--no-figures", action="store_true", help="no PNG figures per point")
    sw.add_argument("--quiet", action="store_true", help="no progress lines")
    _add_session(sw)


def _overrides(pairs, friction_solver=None, friction_law=None, reading=None, args=None):
    from damage_dolfinx.core.parameters import InputError
    out = {} if friction_solver is None else {"friction_solver": friction_solver}
    if args is not None and args.allow_unstable:
        out["stability_check"] = "warn"
    if args is not None and args.allow_long:
        out["allow_long"] = True
    if friction_law is not None:
        out["friction_law"] = friction_law
    if reading is not None:
        out["reading"] = reading
    given = set()
    for pair in pairs:
        if "=" not in pair:
            raise InputError(f"--set expects NAME=VALUE, got {pair!r}")
        name, value = (part.strip() for part in pair.split("=", 1))
        if not name:
            raise InputError(f"--set {pair!r}: no parameter name")
        if name in given or (name in out and name in _SAME_AS_SET):
            raise InputError(f"--set {name}: the parameter is given twice (once is enough; "
                             "which one was meant is not clear)")
        given.add(name)
        out[name] = value
    return out


#: parameters that an option of their own also sets (--friction-solver, --friction-law,
#: --reading): given there and by --set as well is given twice
_SAME_AS_SET = frozenset({"friction_solver", "friction_law", "reading"})

