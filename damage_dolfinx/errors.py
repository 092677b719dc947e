"""The exceptions a caller of the package meets, in one place (all importable from
``damage_dolfinx``), and the wording of their messages on the command line.

* :class:`InputError` (a ValueError): bad input, refused before any work, one line saying why;
* :class:`ConvergenceError` (a RuntimeError): a solver did not converge, or a field left its
  bounds or became NaN/inf; the run is marked "failed" and what was finished stays on disk;
* :class:`OutputError`: an output could not be written (full disk, I/O error);
  the run is marked "failed" where space allows;
* :class:`RunInterrupted` (its ``signum``): the run was stopped by SIGTERM, SIGINT or
  SIGUSR1 at the end of a step, after writing a checkpoint (``restart=True`` goes on).

Messages name the arguments of the Python API (``restart=True``, ``write_every``); the command
line prints them with its flags (:func:`for_command_line`: ``--restart``, ``--write-every``).
"""
from damage_dolfinx.numerics.solvers import ConvergenceError
from damage_dolfinx.parameters import InputError
from damage_dolfinx.runtime.atomic import OutputError
from damage_dolfinx.runtime.signals import RunInterrupted

__all__ = ["InputError", "ConvergenceError", "OutputError", "RunInterrupted", "for_command_line"]

#: API wording -> command-line wording, applied in this order (the command line's refusal already
#: states k_max: the API's way to ask for it before a run is left out there)
_FLAGS = ((" (problem.k_max() gives k_max before the run)", ""), ("restart=True", "--restart"), ("overwrite=True", "--overwrite"),
          ("allow_unstable=True", "--allow-unstable"), ("allow_long=True", "--allow-long"),
          ("another out folder", "another --out"), ("checkpoint_seconds", "--checkpoint-seconds"),
          ("checkpoint_every", "--checkpoint-every"), ("write_every", "--write-every"),
          ("a larger T ", "a larger --T "))


def for_command_line(message: str) -> str:
    """A message of the API with the command line's flags for the arguments it names."""
    for api, flag in _FLAGS:
        message = message.replace(api, flag)
    return message
