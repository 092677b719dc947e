"""The package's logger and the user's logging left alone.

The package logs under ``logging.getLogger("damage_dolfinx")`` (:data:`LOGGER`, and loggers
below it) and never configures the root logger: that is the application's (the command line
sets up its own handler, ``--log-level``). Two parts of the FEniCSx stack do configure it:
FFCx 0.5 calls ``logging.basicConfig()`` and ``logging.captureWarnings(True)`` at import, and
the JIT's C compilation (setuptools' distutils) adds root handlers, logs every build at INFO on
the root logger and resets the root level while doing so. :func:`root_kept` undoes both: the
package's import of the stack and its JIT calls (``compat.form``, ``compat.expression``) run
inside it, so the root logger's handlers, filters and level and the warnings capture are the
user's before and after (a handler FFCx installed before the package was imported, by the
user's own ``import ffcx``, is the user's and stays)."""
from __future__ import annotations

import contextlib
import logging

#: the package's logger (its modules log to children of it: damage_dolfinx.<module>)
LOGGER = logging.getLogger("damage_dolfinx")


@contextlib.contextmanager
def root_kept(quiet=False):
    """The root logger's handlers, filters and level, and whether warnings are captured by
    logging, as they were before the block; ``quiet``: records at INFO and below are not
    emitted during the block (the JIT's build lines)."""
    root = logging.getLogger()
    handlers, filters, level = list(root.handlers), list(root.filters), root.level
    captured = getattr(logging, "_warnings_showwarning", None) is not None
    disabled = logging.root.manager.disable
    if quiet and disabled < logging.INFO:
        logging.disable(logging.INFO)
    try:
        yield
    finally:
        if quiet:
            logging.disable(disabled)
        for handler in [h for h in root.handlers if h not in handlers]:
            root.removeHandler(handler)
        root.handlers[:] = handlers
        root.filters[:] = filters
        root.setLevel(level)
        if not captured and getattr(logging, "_warnings_showwarning", None) is not None:
            logging.captureWarnings(False)


class _Kept:
    """A module loader whose module runs inside :func:`root_kept`."""

    def __init__(self, loader):
        self._loader = loader

    def create_module(self, spec):
        return self._loader.create_module(spec)

    def exec_module(self, module):
        with root_kept():
            self._loader.exec_module(module)

    def __getattr__(self, name):
        return getattr(self._loader, name)


class _FFCxImport:
    """A finder on ``sys.meta_path`` until FFCx is imported (by whichever module imports
    DOLFINx first): its import then runs inside :func:`root_kept`; the finder removes itself."""

    def find_spec(self, name, path=None, target=None):
        if name != "ffcx":
            return None
        keep_root_at_ffcx_import(False)
        import importlib.util
        spec = importlib.util.find_spec(name)
        if spec is not None and spec.loader is not None:
            spec.loader = _Kept(spec.loader)
        return spec


_FINDER = _FFCxImport()


def keep_root_at_ffcx_import(on=True):
    """Install (``on``) or remove the FFCx import finder; nothing to do once FFCx is loaded."""
    import sys
    if _FINDER in sys.meta_path:
        sys.meta_path.remove(_FINDER)
    if on and "ffcx" not in sys.modules:
        sys.meta_path.insert(0, _FINDER)
