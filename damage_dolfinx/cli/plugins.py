"""Plugins of the command line: modules imported before a command (``--plugin``, repeatable,
and the comma-separated ``DAMAGE_DOLFINX_PLUGINS``), which may register models
(``damage_dolfinx.register_model``), examples (``damage_dolfinx.register_example``), friction
solvers or case sources. A plugin is

* a file path (``./my_model.py``, ``models/mine.py``: a name ending in ``.py`` or holding a
  path separator), imported as a module named after the file;
* a module name (``my_model``, ``reproduction.baselines``) found on ``sys.path``, or else in
  the current folder (a console script, unlike ``python -m``, does not put it on the path).
"""
from __future__ import annotations

import os
import sys


def names(given=()) -> list:
    """The plugins of a command: DAMAGE_DOLFINX_PLUGINS first, then the --plugin options."""
    env = os.environ.get("DAMAGE_DOLFINX_PLUGINS", "")
    return [n.strip() for n in env.split(",") if n.strip()] + [n for n in given if n.strip()]


def load(given=()):
    """Import every plugin of the command (InputError, one line, for one that cannot be, or
    that exits or raises while it is imported: the plugin's failure, never the command's end)."""
    from damage_dolfinx.core.parameters import InputError
    for name in names(given):
        name = name.strip()
        try:
            load_one(name)
        except InputError:
            raise
        except SystemExit as exc:  # a plugin may not end the command (exit 0, no run)
            raise InputError(f"plugin {name!r} called sys.exit({exc.code!r}) while being "
                             "imported: the plugin failed") from None
        except KeyboardInterrupt:
            raise
        except BaseException as exc:  # noqa: BLE001 - the plugin's failure, one line
            text = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
            raise InputError(f"plugin {name!r} failed while being imported: "
                             f"{type(exc).__name__}" + (f": {text}" if text else "")) from None


def load_one(name):
    import importlib
    import importlib.util
    from damage_dolfinx.core.parameters import InputError
    where = "--plugin" if name not in os.environ.get("DAMAGE_DOLFINX_PLUGINS", "") \
        else "DAMAGE_DOLFINX_PLUGINS"
    if name.endswith(".py") or os.sep in name or (os.altsep and os.altsep in name):
        path = os.path.abspath(name)
        if not os.path.isfile(path):
            raise InputError(f"{where} names the file {name!r}, which does not exist")
        module_name = os.path.splitext(os.path.basename(path))[0]
        loaded = sys.modules.get(module_name)
        if loaded is not None and os.path.abspath(getattr(loaded, "__file__", "") or "") == path:
            return loaded
        spec = importlib.util.spec_from_file_location(module_name, path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[module_name] = module
        try:
            spec.loader.exec_module(module)
        except Exception:
            sys.modules.pop(module_name, None)
            raise
        return module
    try:
        return importlib.import_module(name)
    except ModuleNotFoundError as exc:
        top = name.split(".")[0]
        if exc.name not in (name, top) or os.getcwd() in sys.path or "" in sys.path:
            raise InputError(f"{where} names {name!r}, which cannot be imported: {exc}") from None
    sys.path.append(os.getcwd())  # the current folder, after everything else on the path
    try:
        return importlib.import_module(name)
    except ImportError as exc:
        sys.path.remove(os.getcwd())
        raise InputError(f"{where} names {name!r}, which cannot be imported (on the path or "
                         f"in the current folder): {exc}") from None
