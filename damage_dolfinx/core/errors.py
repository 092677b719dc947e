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


class InputError(ValueError):
    """Invalid user input; the command line prints the message without a traceback."""


class ConvergenceError(RuntimeError):
    """A PETSc solver did not converge; the message names example, step, time and residual."""


class OutputError(Exception):
    """An output file could not be written (disk full, I/O error, folder deleted); one line."""


class RunInterrupted(Exception):
    """The run stopped on a signal after writing a checkpoint; exit status 128 + signal."""

    def __init__(self, signum: int, message: str):
        super().__init__(message)
        self.signum, self.exit_status = signum, 128 + signum


__all__ = ["InputError", "ConvergenceError", "OutputError", "RunInterrupted", "for_command_line"]

#: API wording -> command-line wording, applied in this order (the command line's refusal already
#: states k_max: the API's way to ask for it before a run is left out there)
_FLAGS = ((" (problem.k_max() gives k_max before the run)", ""), ("restart=True", "--restart"), ("overwrite=True", "--overwrite"),
          ("allow_unstable=True", "--allow-unstable"), ("allow_long=True", "--allow-long"),
          ("another out folder", "another --out"), ("checkpoint_seconds", "--checkpoint-seconds"),
          ("checkpoint_every", "--checkpoint-every"), ("write_every", "--write-every"),
          ("a larger T ", "a larger --T "))


def for_command_line(message: str) -> str:
    """A message of the API with the command line's flags for the arguments it names: the
    phrases of _FLAGS, and a refusal that starts with an argument's name (``k must be > 0``,
    from the one check of that argument, core.validation) starts with its flag (``--k``)."""
    import re
    from damage_dolfinx.core.validation import ARGUMENTS
    for api, flag in _FLAGS:
        message = message.replace(api, flag)
    head = re.match(r"(?:(damage-dolfinx: \w+: ))?(\w+)( must )", message)
    if head and head.group(2) in ARGUMENTS and head.group(2) not in ("comm", "on_step"):
        start, end = head.span(2)
        message = message[:start] + "--" + head.group(2).replace("_", "-") + message[end:]
    return message
