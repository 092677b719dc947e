"""PETSc options of the command line and of the API (``petsc_options=`` of ``run``, ``steps``,
``converge``, ``sweep``; :func:`petsc_options_from_argv` for a script's own command line),
checked alike, each check in one place: a name outside the package's solver prefixes
(PETSC_PREFIXES, :func:`_check_name`) is refused (the command line suggests the double-dash
option it resembles), a value PETSc refuses is refused before any work
(:func:`_check_petsc_values`), and an option no solver read is named in a warning at the end
(:func:`_unused`). The API's options hold for the one call only (:func:`scoped`)."""
from __future__ import annotations

import argparse
import sys

from mpi4py import MPI

from damage_dolfinx.core.petsc_names import (PETSC_GLOBAL, PETSC_PREFIXES,  # noqa: F401
                                               _check_name, normalised)


#: the part of an option name after which the PETSc object's own options start
_OBJECT_PARTS = ("snes_", "ksp_", "pc_")


def _petsc_options(tokens, parser, command):
    """Check the tokens argparse did not know and put the PETSc options among them into the
    options database; returns {name: value} of those set. Raises InputError for a single-dash
    word that is no PETSc option of the package's solvers (suggesting the double-dash option),
    an unknown double-dash option and a stray word."""
    from petsc4py import PETSc
    from damage_dolfinx.core.parameters import InputError
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
        _check_name(name, lambda: _suggestion("--" + name, parser, command))
        given[name] = value if value is not None else ""
        i += 2 if value is not None else 1
    opts = PETSc.Options()
    for name, value in given.items():
        opts[name] = value
    return given


def petsc_options_from_argv(argv=None) -> dict:
    """The PETSc options of a script's command line, for ``petsc_options=`` of
    :func:`~damage_dolfinx.run` (and ``steps``, ``converge``, ``sweep``)::

        # python my_run.py -mech_ksp_type cg -damage_snes_monitor
        dd.run(problem, "results/mine", petsc_options=dd.petsc_options_from_argv())

    ``argv``: the words to read (default ``sys.argv[1:]``; a script with options of its own
    passes what its parser left, ``parser.parse_known_args()[1]``). Every single-dash word
    (``-name``, not a number) is a PETSc option, its value the next word unless that is an
    option too; a double-dash option and any other word are the script's and skipped. A
    single-dash name outside the package's solver prefixes is refused (InputError), as on the
    command line; values are checked by the run itself, before any work."""
    import sys as _sys
    tokens = list(_sys.argv[1:] if argv is None else argv)
    if not all(isinstance(t, str) for t in tokens):
        from damage_dolfinx.core.parameters import InputError
        raise InputError("petsc_options_from_argv: argv is a list of strings")
    out, i = {}, 0
    while i < len(tokens):
        tok = tokens[i]
        if tok.startswith("-") and not tok.startswith("--") and len(tok) > 1 and _is_option(tok):
            value = tokens[i + 1] if i + 1 < len(tokens) and not _is_option(tokens[i + 1]) \
                else ""
            _check_name(tok[1:])
            out[tok[1:]] = value
            i += 2 if value != "" else 1
        else:
            i += 1
    return out


class scoped:
    """The API's PETSc options for one call (a context manager, collective under MPI): checked
    on entry (names, then values on throwaway solvers: InputError before any work), in the
    options database during the call, then removed, the database's earlier values of the same
    names restored; an option no solver of the call read is warned about on leaving
    (``UserWarning`` on rank 0)."""

    def __init__(self, options, comm, what="run"):
        self.given = normalised(options)
        self.comm, self.what, self._before = comm, what, {}

    def __enter__(self):
        if not self.given:
            return self
        from petsc4py import PETSc
        opts = PETSc.Options()
        self._before = {n: opts.getString(n) for n in self.given if opts.hasName(n)}
        for name, value in self.given.items():
            opts[name] = value
        try:
            _check_petsc_values(self.given)
        except BaseException:
            self._restore()
            raise
        return self

    def __exit__(self, exc_type, exc, tb):
        if not self.given:
            return False
        try:
            if exc_type is None:
                unused = _unused(self.given, self.comm)
                if unused and self.comm.rank == 0:
                    import warnings
                    warnings.warn(f"no solver of this {self.what} read the PETSc option(s) "
                                  f"{' '.join(unused)}: they had no effect", UserWarning,
                                  stacklevel=3)
        finally:
            self._restore()
        return False

    def _restore(self):
        from petsc4py import PETSc
        opts = PETSc.Options()
        for name in self.given:
            opts.delValue(name)
        for name, value in self._before.items():
            opts[name] = value


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
    from damage_dolfinx.core.parameters import InputError
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
    import numpy as np  # (not at the top: --help loads no numpy)
    used = np.array(used, dtype=np.int32)
    if names:  # element-wise (the pickling allreduce compares whole arrays: two or more fail)
        comm.Allreduce(MPI.IN_PLACE, used, op=MPI.MAX)
    return [f"-{n}" for n, u in zip(names, used) if not u]


def _forget(given):
    """Remove the options of this command, and the solvers' defaults, from the PETSc database
    (a later command in the same process, e.g. the tests, starts clean)."""
    if "petsc4py.PETSc" not in sys.modules:  # nothing was set (--help: no PETSc loaded)
        return
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
