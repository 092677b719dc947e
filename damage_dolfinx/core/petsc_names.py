"""The names of the package's PETSc options: the solver prefixes, the global diagnostics, and
the check of a name and of an API ``petsc_options`` mapping (its values are checked by PETSc
itself, on throwaway solvers: problem/petsc_options.py)."""
from __future__ import annotations

#: prefixes of the package's PETSc solvers (an option -<prefix><name> reaches one of them)
PETSC_PREFIXES = ("mech_", "damage_", "friction_", "uzawa_", "pd_", "stability_")
#: PETSc options without a solver prefix that are accepted (diagnostics of the whole run)
PETSC_GLOBAL = ("log_view", "options_left", "options_view", "info", "malloc_dump",
                "memory_view", "log_trace")


def _check_name(name, hint=lambda: ""):
    """A PETSc option name (without its dash) of the package's solvers, or InputError; ``hint``
    gives what to add to the message (the command line: the double-dash option it resembles)."""
    from damage_dolfinx.core.errors import InputError
    if not isinstance(name, str) or not name:
        raise InputError(f"a PETSc option name is a non-empty string, got {name!r}")
    if not (name.startswith(PETSC_PREFIXES) or name in PETSC_GLOBAL):
        raise InputError(f"unknown option -{name}: not a PETSc option of this program's "
                         f"solvers (prefixes {', '.join(PETSC_PREFIXES)}){hint()}")


def normalised(options) -> dict:
    """``petsc_options`` of the API -> {name: value string}: a mapping of names (with or
    without the dash) to values (str, int, float, bool; None or "" for a flag); InputError for
    a name outside the package's prefixes or a value of another type."""
    import math
    import numbers
    from damage_dolfinx.core.errors import InputError
    if options is None:
        return {}
    if isinstance(options, (str, bytes)) or not hasattr(options, "items"):
        raise InputError("petsc_options must be a mapping {name: value}, e.g. "
                         "{'mech_ksp_type': 'cg'} (a script's command line: "
                         "petsc_options=dd.petsc_options_from_argv()), got "
                         f"{type(options).__name__}")
    out = {}
    for key, value in options.items():
        name = key[1:] if isinstance(key, str) and key.startswith("-") else key
        _check_name(name)
        if value is None:
            value = ""
        elif isinstance(value, bool):
            value = "true" if value else "false"
        elif isinstance(value, numbers.Real) and not isinstance(value, bool):
            if not math.isfinite(float(value)):
                raise InputError(f"petsc_options: -{name} must be finite, got {value}")
            value = repr(value.item() if hasattr(value, "item") else value)
        elif not isinstance(value, str):
            raise InputError(f"petsc_options: the value of -{name} is a string or a number, "
                             f"got {type(value).__name__}")
        if name in out:
            raise InputError(f"petsc_options: -{name} is given twice")
        out[name] = value
    return out
