"""What every model reports besides its scheme: the common scalars (norms of u and zeta from
operators assembled once), the contact resultant on Gamma_C, the iteration totals, the
summary keys and the mesh information. :class:`Reporting` is a base of
:class:`~damage_dolfinx.Model`; a model overrides :meth:`Reporting.contact_pressure`,
:meth:`Reporting.summary_extra` or :meth:`Reporting.scalars` (extending
:meth:`Reporting.base_scalars`) where it reports more."""
from __future__ import annotations

import numpy as np
import ufl
from mpi4py import MPI

from damage_dolfinx import compat
from damage_dolfinx.numerics import bookkeeping


class Reporting:
    """The reports of a model built on ``self.u``, ``self.zeta``, ``self.mesh``, ``self.comm``
    and ``self.data`` (set by :class:`~damage_dolfinx.Model`'s constructor), and on the
    model's ``contact_quadrature_degree`` declaration."""

    # -- scalars
    def zeta_min(self) -> float:
        owned = self.zeta.x.array[:self.zeta.function_space.dofmap.index_map.size_local]
        return self.comm.allreduce(owned.min() if owned.size else np.inf, op=MPI.MIN)

    def zeta_max(self) -> float:
        owned = self.zeta.x.array[:self.zeta.function_space.dofmap.index_map.size_local]
        return self.comm.allreduce(owned.max() if owned.size else -np.inf, op=MPI.MAX)

    def scalars(self) -> dict:
        """||u||_L2, ||eps(u)||_L2, min/max/mean zeta (the summary.json 'final' block), from
        matrices assembled once: u^T M u, u^T K_eps u and m . zeta with m_i = int phi_i (exact
        for P1 fields; no assembly per step), in one reduction."""
        return self.base_scalars()[0]

    def base_scalars(self, sums=()) -> tuple:
        """(the scalars of :meth:`scalars`, the sums over ranks of this rank's values ``sums``),
        all in the same reduction."""
        norms = self.field_norms()
        parts = norms.u_parts()
        zeta_integral, lo, hi = norms.zeta_parts()
        (u_L2_sq, eps_sq, zeta_integral, *totals), (neg_min, zeta_max) = \
            bookkeeping.sums_and_maxima(self.comm, parts + [zeta_integral, *sums], [-lo, hi])
        return {"u_L2": float(np.sqrt(max(u_L2_sq, 0.0))), "eps_u_L2": float(np.sqrt(max(eps_sq, 0.0))),
                "zeta_min": -neg_min, "zeta_max": zeta_max,
                "zeta_mean": float(zeta_integral / norms.area)}, totals

    def field_norms(self) -> bookkeeping.FieldNorms:
        """The norm operators of u and zeta with their owned views (built at the first call)."""
        norms = getattr(self, "_field_norms", None)
        if norms is None:
            norms = self._field_norms = bookkeeping.FieldNorms(self.u, self.zeta)
        return norms

    # -- contact
    def contact_pressure(self):
        """The normal contact pressure on Gamma_C as a UFL expression of the live Functions
        (None: the model has no normal-compliance contact)."""
        return None

    def contact_resultant(self):
        """int_{Gamma_C} p nu ds, the force of the foundation's pressure on the body, as a
        NumPy vector on every rank (None without normal contact); forms compiled once."""
        if not hasattr(self, "_resultant_forms"):
            p = self.contact_pressure()
            if p is None:
                self._resultant_forms = None
            else:
                from damage_dolfinx.core.tags import GAMMA_C
                n = ufl.FacetNormal(self.mesh)
                degree = self.contact_quadrature_degree
                ds = ufl.Measure("ds", domain=self.mesh,
                                 subdomain_data=self.data.geometry.facet_tags,
                                 metadata={} if degree is None else {"quadrature_degree": degree})
                self._resultant_forms = [compat.form(p * n[i] * ds(GAMMA_C))
                                         for i in range(self.mesh.geometry.dim)]
        if self._resultant_forms is None:
            return None
        return np.array([compat.assemble_scalar(f, self.comm) for f in self._resultant_forms])

    def iteration_totals(self) -> dict:
        return {}

    def summary_extra(self) -> dict:
        """Problem-specific summary.json keys (e.g. a failure load); none by default."""
        return {}

    def mesh_info(self) -> dict:
        tdim = self.mesh.topology.dim
        info = {"cells": self.mesh.topology.index_map(tdim).size_global,
                "vertices": self.mesh.topology.index_map(0).size_global,
                "h": self.data.geometry.h, "description": self.data.geometry.description}
        for name, f in (("u", getattr(self, "u", None)), ("zeta", getattr(self, "zeta", None))):
            if f is not None:
                V = f.function_space
                info[f"dofs_{name}"] = V.dofmap.index_map.size_global * V.dofmap.index_map_bs
        return info
