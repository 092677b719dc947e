"""What a run hands over to the caller after each step (:class:`Step`), and the default
checkpoint interval."""
from __future__ import annotations

#: default wall-time interval between checkpoints (seconds)
CHECKPOINT_SECONDS = 120.0


class Step:
    """What a run hands over after each step: ``n``, ``t``, the ``model`` and its live
    Functions ``u``, ``zeta``, ``v`` (None where the scheme has none), the run's ``summary``
    (so far), ``contact_pressure`` (the model's UFL pressure on Gamma_C, None without normal
    contact) and :meth:`contact_resultant`."""

    def __init__(self, run):
        self._run = run

    model = property(lambda self: self._run.stepper)
    n = property(lambda self: self._run.stepper.n)
    t = property(lambda self: self._run.stepper.t)
    u = property(lambda self: self._run.stepper.u)
    zeta = property(lambda self: self._run.stepper.zeta)
    v = property(lambda self: getattr(self._run.stepper, "v", None))
    summary = property(lambda self: self._run.summary)
    contact_pressure = property(lambda self: self._run.stepper.contact_pressure())

    def contact_resultant(self):
        """int_{Gamma_C} p nu ds (a vector, every rank; None without normal contact)."""
        return self._run.stepper.contact_resultant()
