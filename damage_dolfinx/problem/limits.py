"""The time-step limit of a problem before its run: ``Problem.k_max()``.

The schemes are explicit in some terms (docs/models.md, "Stability of the explicit terms"):

* 2.2: the explicit elastic term, k_max = 2/m_visc; 2.4: the explicit viscoplastic rate,
  k_max = 2/(1 - zeta*) (Model.k_max); 2.1 and 2.3: none (k_max = inf);
* 3.1, 3.2, 3.3: the explicit elastic (and normal compliance) forces,
  rho (v_n - v_{n-1})/k + A eps(v_n) = -B eps(u_{n-1}) - c_nu (u_{n-1}.nu)_+ ..., stable iff
  k <= k_max, the smallest k at which 4M + 2kC - k^2 (K_B + K_c) is singular (with
  C = K_B/m_visc); it depends on the mesh, E, nu, rho, m_visc and c_nu, and is computed by the
  model exactly as for the run's own check (numerics/stability.py), so the value given here is
  the one a run compares its k with.
"""
from __future__ import annotations

import dataclasses
import math

from mpi4py import MPI


def k_max(problem, comm=MPI.COMM_WORLD) -> float:
    """k_max of ``problem``'s scheme on its mesh with its data (math.inf: no explicit term).
    Collective on ``comm``; a dynamic model builds the problem's mesh and operators once."""
    from damage_dolfinx.models.registry import model
    info = model(problem.model)
    if not info.dynamic:
        return float(info.k_max(problem.parameters()))
    T = float(problem.T)
    small = T * 1e-6  # far below any limit: the model computes k_max without a warning
    ex = dataclasses.replace(problem, k=small, allow_unstable=True).checked()
    from damage_dolfinx.numerics.stability_bound import exact_estimates
    with exact_estimates():  # the eigensolved limit, not only the cheap bound below it
        stepper = ex.build(comm, ex.n, small, T)
    from damage_dolfinx.models.contracts import mesh_k_max
    return mesh_k_max(stepper)  # Model.mesh_k_max, checked (inf: no limit)
