"""PETSc options on the command line: single-dash words reach the package's solvers (prefixes
PETSC_PREFIXES); any other single-dash word is refused with the double-dash option it
resembles, a value PETSc refuses is refused before any work, and an option no solver read is
named in a warning at the end."""
from __future__ import annotations

import argparse
import sys

from mpi4py import MPI


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
