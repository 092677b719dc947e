"""PETSc options of the command line and of the API (``petsc_options=`` of ``run``, ``steps``,
``converge``, ``sweep``; :func:`petsc_options_from_argv` for a script's own command line),
checked alike, each check in one place: a name outside the package's solver prefixes
(PETSC_PREFIXES, :func:`_check_name`) is refused (the command line suggests the double-dash
option it resembles), a value PETSc refuses is refused before any work
(:func:`_check_petsc_values`), and an option no solver read is named in a warning at the end
(:func:`_unused`). The API's options hold for the one call only (:func:`scoped`). Options a
script put into ``PETSc.Options()`` by hand meet the same checks when a call starts
(:func:`_database_options`): a prefix that misspells one of the package's is refused, the
values under the package's prefixes are checked, and those no solver read are warned about."""
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
    _COMMAND_LINE.update(given)
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
        self.comm, self.what, self._before, self.by_hand = comm, what, {}, {}

    def __enter__(self):
        # options a script put into PETSc.Options() by hand, checked as the given ones are
        self.by_hand = _agreed_database_options(set(self.given), self.comm)
        if not self.given and not self.by_hand:
            return self
        from petsc4py import PETSc
        opts = PETSc.Options()
        self._before = {n: opts.getString(n) for n in self.given if opts.hasName(n)}
        for name, value in self.given.items():
            opts[name] = value
        try:
            _check_petsc_values({**self.by_hand, **self.given}, set(self.by_hand))
        except BaseException:
            self._restore()
            raise
        _MANAGED.append(set(self.given) | set(self.by_hand))
        return self

    def __exit__(self, exc_type, exc, tb):
        if not self.given and not self.by_hand:
            return False
        _MANAGED.pop()
        try:
            if exc_type is None:
                unused = _unused(self.given, self.comm)
                by_hand = _unused(self.by_hand, self.comm)
                if (unused or by_hand) and self.comm.rank == 0:
                    import warnings
                    where = (" (set in the PETSc options database before the call)"
                             if by_hand else "")
                    warnings.warn(f"no solver of this {self.what} read the PETSc option(s) "
                                  f"{' '.join(unused + by_hand)}{where}: they had no effect",
                                  UserWarning, stacklevel=3)
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


def _check_petsc_values(given, by_hand=()):
    """Every PETSc option given is applied to a throwaway SNES (with its KSP and PC) of its
    prefix, so that a value PETSc refuses (-mech_ksp_type nonsense) is refused now, before any
    work, with one line; the options are then set anew, so that whether a solver of the run
    reads them (``_unused``) is not confused by this check. ``by_hand``: the names found in
    the options database (:func:`_database_options`), so named in the refusal."""
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
            where = (" (set in the PETSc options database)"
                     if any(n.startswith(prefix) for n in by_hand) else "")
            raise InputError(f"PETSc refuses the options {options}{where}: {reason}") from None
        finally:
            snes.destroy()
    opts = PETSc.Options()
    for name, value in given.items():
        opts.delValue(name)
        opts[name] = value


#: the option names an active call or the command line put into the database itself (checked
#: there): a call inside another (a sweep's points, a command's run) does not take them for
#: options set by hand
_MANAGED = []
_COMMAND_LINE = set()


def _near_prefix(name):
    """The name ``name`` meant, when its prefix (the part before its ``ksp_``, ``snes_`` or
    ``pc_``) misspells one of the package's (``mehc_ksp_type`` -> ``mech_ksp_type``), or None: one of four characters or
    more, close to a prefix (difflib ratio >= 0.75, letters' case ignored), or a prefix with two
    letters swapped."""
    import difflib
    cut = [name.find(part) for part in _OBJECT_PARTS if name.find(part) > 0]
    if not cut:
        return None
    head, rest = name[:min(cut)].lower(), name[min(cut):]
    if head in PETSC_PREFIXES:
        return None
    for prefix in PETSC_PREFIXES:
        if sorted(head) == sorted(prefix) and sum(a != b for a, b in zip(head, prefix)) == 2:
            return prefix + rest
    close = difflib.get_close_matches(head, PETSC_PREFIXES, n=1, cutoff=0.75)
    return close[0] + rest if close and len(head) >= 4 else None


def _database_options(skip=()):
    """The options a script put into ``PETSc.Options()`` by hand before a call (or PETSc read
    at its start), checked as the command line checks its own: a name whose prefix misspells
    one of the package's (``mehc_ksp_type``) is refused (InputError, one line, before any
    work); returns {name: value} of those under the package's prefixes (their values are then
    checked, and those no solver read warned about), leaving out ``skip``, the options the
    package put there itself (its solvers' defaults) and those of an enclosing call or of the
    command line. Options of other prefixes (a script's own solvers) are left alone."""
    if "petsc4py.PETSc" not in sys.modules:
        return {}
    from petsc4py import PETSc
    from damage_dolfinx.core.errors import InputError
    managed = set(skip) | _COMMAND_LINE
    for names in _MANAGED:
        managed |= names
    solvers = sys.modules.get("damage_dolfinx.numerics.solvers")
    opts = PETSc.Options()
    found = {}
    for name, value in sorted(opts.getAll().items()):
        if name in managed:
            continue
        if solvers is not None and solvers._ours(opts, name):
            continue  # a default of the package's solvers
        near = _near_prefix(name)
        if near is not None:
            raise InputError(f"unknown PETSc option -{name} in the options database: not an "
                             f"option of this program's solvers (prefixes "
                             f"{', '.join(PETSC_PREFIXES)}); did you mean -{near}?")
        if name.startswith(PETSC_PREFIXES):
            found[name] = "" if value is True else str(value)
    return found


def _agreed_database_options(skip, comm):
    """:func:`_database_options` on every rank of ``comm``, one outcome for all: a refusal on
    any rank is raised on every rank, and so are options set by hand that differ between
    ranks (the check of which were read compares them rank by rank)."""
    from damage_dolfinx.core.errors import InputError
    try:
        found, error = _database_options(skip), None
    except InputError as exc:
        found, error = {}, str(exc)
    if comm.size > 1:
        gathered = comm.allgather((error, sorted(found.items())))
        error = next((e for e, _ in gathered if e), None)
        if error is None and any(items != gathered[0][1] for _, items in gathered):
            error = ("the PETSc options set by hand under the package's prefixes differ "
                     "between the ranks: " + "; ".join(
                         f"rank {r}: " + (" ".join(f"-{n} {v}".strip() for n, v in items)
                                          or "none") for r, (_, items) in enumerate(gathered)))
    if error:
        raise InputError(error)
    return found


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
    _COMMAND_LINE.difference_update(given)
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
