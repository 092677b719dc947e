"""PETSc: the value that switches a tolerance off, and whether a solver read an option."""
from __future__ import annotations

from petsc4py import PETSc

#: "no limit" for a PETSc tolerance (switches a test off): -1 up to PETSc 3.21; from 3.22 on -1 is
#: PETSC_DETERMINE (the default value, e.g. divtol 1e4) and PETSC_UNLIMITED = -3 switches it off
PETSC_UNLIMITED = int(getattr(PETSc, "UNLIMITED", -1))


_PETSC_LIBRARY = []


def petsc_option_used(name: str):
    """Whether a solver read the PETSc option ``name`` (no leading dash) since it was set
    (PetscOptionsUsed; petsc4py 3.18 has no binding for it), or None where the PETSc library
    cannot be found."""
    import ctypes
    if not _PETSC_LIBRARY:
        path = None
        try:
            with open("/proc/self/maps") as maps:
                path = next((line.split()[-1] for line in maps
                             if "/libpetsc" in line and ".so" in line), None)
        except OSError:
            pass
        try:
            _PETSC_LIBRARY.append(ctypes.CDLL(path) if path else None)
        except OSError:
            _PETSC_LIBRARY.append(None)
    lib = _PETSC_LIBRARY[0]
    if lib is None or not hasattr(lib, "PetscOptionsUsed"):
        return None
    flag = ctypes.c_int(0)
    if lib.PetscOptionsUsed(None, name.encode(), ctypes.byref(flag)) != 0:
        return None
    return bool(flag.value)
