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
line prints them with its flags (``--restart``, ``--write-every``: cli/wording.py).
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


__all__ = ["InputError", "ConvergenceError", "OutputError", "RunInterrupted"]
