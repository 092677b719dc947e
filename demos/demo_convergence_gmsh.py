r"""
Convergence on a gmsh mesh family (plate with a hole)
=====================================================

:func:`damage_dolfinx.converge` on meshes that are *not nested*: a plate
:math:`(0, 2) \times (0, 1)` with a hole of radius :math:`0.25`, meshed by gmsh at
:math:`h = 0.4 / n`. Each coarse solution is compared with the reference on the reference
mesh by exact point evaluation: its value at every node of the reference mesh (P1 fields) is
computed in the coarse cell that contains the node, and the error is integrated on the
reference mesh,

.. math::

   e(h, k) = \max_{t_n} \Bigl(\|u_{\mathrm{ref}} - I_h u_{hk}\|_V
   + \|\zeta_{\mathrm{ref}} - I_h \zeta_{hk}\|_{L^2}\Bigr)(t_n),
   \qquad \|v\|_V = \|\varepsilon(v)\|_{L^2}.

What to take away: a gmsh family ``(comm, n) -> mesh`` needs nothing more than a structured
one; the boundary parts are named by the gmsh physical names (``"left"``, ``"right"``).
"""

# %%
# Mesh family and problem
# -----------------------
# :func:`~damage_dolfinx.geometries.plate_with_hole.plate_with_hole_family` builds the plate at
# level :math:`n` with the physical groups ``left``, ``right``, ``bottom``, ``top`` and
# ``hole``. The elastic model ``"2.1"`` is clamped on the left and pulled on the right by
# :math:`(40\,t, 0)` up to :math:`T = 0.4`; the hole concentrates the strain and the damage.

import os
from pathlib import Path

import ufl
from mpi4py import MPI

import damage_dolfinx as dd
from damage_dolfinx.geometries.plate_with_hole import plate_with_hole_family

comm = MPI.COMM_WORLD
out = Path(os.environ.get("DAMAGE_DOLFINX_DEMO_OUT", "results")) / "convergence_gmsh"

problem = dd.Problem(
    model="2.1", mesh=plate_with_hole_family(h0=0.4), n=1, T=0.4, name="plate with a hole",
    boundaries={"clamped": "left", "traction": "right"},
    traction=lambda x, t: ufl.as_vector((40.0 * t, 0.0)),
    params={"E": 1e3, "kappa": 0.1, "lam_u_plus": 3e3, "lam_u_minus": 3e3,
            "stop_at_zeta_star": False})

# %%
# The study
# ---------
# Levels :math:`n = 1, 2, 4` (:math:`h = 0.4, 0.2, 0.1`) and :math:`k = 0.1, 0.05, 0.025`
# against the reference :math:`n = 8` (:math:`h = 0.05`), :math:`k = 0.0125`. ``summary.json`` states how
# the meshes were compared (``comparison``) and the norm (``norm``).

study = dd.converge(problem, out, n=[1, 2, 4], k=[0.1, 0.05, 0.025], ref_n=8, ref_k=0.0125,
                    progress=False)
rates = study["rates"]
if comm.rank == 0:
    print(f"compared by: {study['comparison']}")
    print(f"norm: {study['norm']}")
    for r in study["errors"]:
        print(f"n = {r['n']} (h = {r['h']:.3g}), k = {r['k']:g}: error {r['error']:.4e}")
    print(f"rates: in h + k (all cells) {rates['h_plus_k_all']:.3f}, in h at k = 0.025 "
          f"{rates['h_at_smallest_k']:.3f}, in k at n = 4 {rates['k_at_finest_n']:.3f}")

# %%
# Check
# -----
# The errors fall with :math:`h + k` (first-order elements and steps: a rate near 1).

rate = rates["h_plus_k_all"]
verdict = "PASS" if 0.5 <= rate <= 2.0 else "FAIL"
if comm.rank == 0:
    print(f"PHYSICS_CHECK convergence_rate_gmsh {abs(rate - 1):.3e} 1e+00 {verdict}")
assert verdict == "PASS", rate

# %%
# The plot ``convergence.png`` (written by the study):

if comm.rank == 0:
    import matplotlib.image
    import matplotlib.pyplot as plt

    image = matplotlib.image.imread(out / "convergence.png")
    fig, ax = plt.subplots(figsize=(4.5, 4.5 * image.shape[0] / image.shape[1]))
    ax.imshow(image)
    ax.axis("off")
