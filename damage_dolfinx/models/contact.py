"""What the normal-compliance models (2.3, 3.1, and yours) share: the contact pressure of the
current state and the RMS penetration over Gamma_C, written once."""
from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem

from damage_dolfinx import compat


class NormalComplianceScalars:
    """Mixin of a :class:`~damage_dolfinx.Model` with ``self.u``, ``self.n_facet`` (the outward
    normal), ``self.c_nu`` and ``self.gap``: call :meth:`_contact_setup` with the measure of
    Gamma_C once the unknowns exist."""

    def _contact_setup(self, dsC):
        """The RMS penetration form int_{Gamma_C} (u.nu - gap)_+^2 and |Gamma_C|."""
        self._penetration = compat.form(
            ufl.max_value(ufl.dot(self.u, self.n_facet) - self.gap, 0.0) ** 2 * dsC)
        self._contact_length = compat.assemble_scalar(fem.Constant(self.mesh, 1.0) * dsC,
                                                      self.comm)

    def penetration_rms(self) -> float:
        """sqrt(int_{Gamma_C} (u.nu - gap)_+^2 / |Gamma_C|) (0 without a contact part)."""
        length = self._contact_length
        pen = compat.assemble_scalar(self._penetration, self.comm) if length > 0 else 0.0
        return float(np.sqrt(pen / length)) if length > 0 else 0.0

    def contact_pressure(self):
        """p_nu(u_n.nu - gap) = c_nu (u_n.nu - gap)_+ on Gamma_C."""
        from damage_dolfinx.forms.contact import normal_compliance_pressure
        return normal_compliance_pressure(self.u, self.n_facet, self.c_nu, self.gap)
