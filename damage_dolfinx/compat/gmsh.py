"""gmsh, imported on first use and keeping the process's SIGINT handler, and one gmsh session
per process."""
from __future__ import annotations

import signal
import threading


def import_gmsh_keeping_sigint():
    """gmsh's Python module sets SIGINT to its default action (killing the process, with no
    line and no status) when it is first imported: import it now, if it is there, and put the
    handler back. Every import of gmsh in the package goes through here, where gmsh is first
    needed (its import takes a noticeable part of a small run's start, which a run on a
    built-in mesh does not pay)."""
    import sys
    if "gmsh" in sys.modules or threading.current_thread() is not threading.main_thread():
        return
    handler = signal.getsignal(signal.SIGINT)
    try:
        import gmsh  # noqa: F401
    except Exception:  # noqa: BLE001 - no gmsh: nothing to protect against
        pass
    finally:
        if handler is not None:
            signal.signal(signal.SIGINT, handler)


_gmsh_ready = False


class _LazyGmsh:
    """The gmsh module, imported on first use: its import is slow, and a run on a built-in
    mesh never needs it (the geometry modules are imported with the catalogue)."""

    def __getattr__(self, name):
        return getattr(_gmsh(), name)


def _gmsh():
    """The gmsh module, imported keeping the SIGINT handler."""
    import_gmsh_keeping_sigint()
    import gmsh
    return gmsh


#: ``from damage_dolfinx.compat.gmsh import lazy_gmsh as gmsh`` in the gmsh-built geometries
lazy_gmsh = _LazyGmsh()


def gmsh_session():
    """Initialise gmsh once per process (gmsh 4.8 has no isInitialized) and silence it."""
    global _gmsh_ready
    gmsh = _gmsh()
    if not _gmsh_ready:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        _gmsh_ready = True
    return gmsh
