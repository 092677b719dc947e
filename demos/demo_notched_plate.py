r"""
Notched plate in tension (model 2.1)
====================================

A plate with two semicircular edge notches is pulled at both ends. By symmetry only a quarter
is meshed: the cut planes :math:`x = 0` and :math:`y = 0` are rollers (bilateral contact,
:math:`u \cdot \nu = 0`), the end :math:`x = 4` carries the traction :math:`(t_0\, t, 0)`.

The quasistatic elastic model with damage (model ``"2.1"``) degrades the plane-stress
elasticity :math:`\mathcal{B}` with the damage field :math:`\zeta \in [\zeta_*, 1]`
(:math:`\zeta = 1`: sound material), which diffuses and is driven by the strain energy:

.. math::

   -\operatorname{div} \bigl(\eta_*(\zeta)\, \mathcal{B}\,\varepsilon(u)\bigr) = 0,
   \qquad
   \dot\zeta - \kappa \Delta \zeta = \phi\bigl(\varepsilon(u), \zeta\bigr),
   \qquad \eta_*(\zeta) = \max(\zeta, \zeta_*),

with the tension/compression law of variant B,
:math:`\phi = \lambda_D \frac{1 - \zeta}{\eta_*(\zeta)} - \frac{\lambda_u^+}{2}
\Psi(\varepsilon^+) - \frac{\lambda_u^-}{2} \Psi(\varepsilon^-)`.

What to take away: the damage concentrates at the notch root, where the strain is largest,
while far from the notch the bar carries the uniaxial stress :math:`\sigma_{xx} = t_0\, t`
whatever the damage there: the section is statically determinate, so equilibrium alone fixes it.
"""

# %%
# Mesh
# ----
# The quarter plate :math:`(0, 4) \times (0, 1)` minus the notch, a disc of radius 0.3 centred
# at :math:`(0, 1)`, is drawn and meshed with gmsh on rank 0 and distributed by
# :func:`damage_dolfinx.from_gmsh`. The physical curves tag the boundary parts:
# 1 the cut :math:`x = 0`, 2 the loaded end :math:`x = 4`, 3 the cut :math:`y = 0`, 4 the
# rest (traction free: no role).

import os
from pathlib import Path

import numpy as np
import ufl
from mpi4py import MPI

import damage_dolfinx as dd
from damage_dolfinx.geometries import gmsh_session

comm = MPI.COMM_WORLD
out = Path(os.environ.get("DAMAGE_DOLFINX_DEMO_OUT", "results")) / "notched_plate"

gmsh = gmsh_session()
if comm.rank == 0:
    gmsh.model.add("notched_plate")
    plate = gmsh.model.occ.addRectangle(0, 0, 0, 4, 1)
    notch = gmsh.model.occ.addDisk(0, 1, 0, 0.3, 0.3)
    gmsh.model.occ.cut([(2, plate)], [(2, notch)])
    gmsh.model.occ.synchronize()
    parts = {}
    for _, curve in gmsh.model.getEntities(1):
        x, y, _ = gmsh.model.occ.getCenterOfMass(1, curve)
        if abs(x) < 1e-9:
            tag = 1
        elif abs(x - 4) < 1e-9:
            tag = 2
        else:
            tag = 3 if abs(y) < 1e-9 else 4
        parts.setdefault(tag, []).append(curve)
    for tag, curves in parts.items():
        gmsh.model.addPhysicalGroup(1, curves, tag)
    gmsh.model.addPhysicalGroup(2, [s for _, s in gmsh.model.getEntities(2)], 1)
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.2)
    for _, point in gmsh.model.getEntities(0):  # finer at the ends of the notch's arc
        x, y, _ = gmsh.model.getValue(0, point, [])
        if abs(np.hypot(x, y - 1) - 0.3) < 1e-9:
            gmsh.model.mesh.setSize([(0, point)], 0.04)
    gmsh.model.mesh.generate(2)
geometry = dd.from_gmsh(comm=comm)
if comm.rank == 0:
    gmsh.model.remove()
cells = geometry.mesh.topology.index_map(2).size_global
if comm.rank == 0:
    print(f"{cells} triangles")

# %%
# Model
# -----
# The model's defaults (:func:`damage_dolfinx.model_defaults`) with a small diffusion
# :math:`\kappa = 0.01`, so that the damage stays where it starts, and no damage in
# compression (:math:`\lambda_u^- = 0`). The traction grows to :math:`t_0 = 200` at
# :math:`T = 1` in 20 steps; :math:`E = 10^4`.

t0 = 200.0
problem = dd.Problem(
    model="2.1", mesh=geometry, T=1.0, k=0.05, name="notched-plate",
    boundaries={"bilateral": [1, 3], "traction": 2},
    traction=lambda x, t: ufl.as_vector((t0 * t, 0.0)),
    params={"kappa": 0.01, "lam_u_plus": 1000.0, "lam_u_minus": 0.0})

# %%
# Run
# ---
# :func:`damage_dolfinx.run` writes the run folder (``summary.json``, ``history.csv``,
# ``fields.xdmf`` for ParaView, ``fields_final.npz``, the figure of the final fields).

summary = dd.run(problem, out, overwrite=True, progress=False)
final = summary["final"]
if comm.rank == 0:
    print(f"{summary['status']}: {summary['steps_done']} steps on {comm.size} rank(s), "
          f"zeta in [{final['zeta_min']:.4f}, {final['zeta_max']:.4f}]")

# %%
# Physics check
# -------------
# In the strip :math:`2.5 < x < 3.5`, far from the notch, the stress is uniaxial and equals the
# applied traction: the von Mises stress of plane stress is :math:`|\sigma_{xx}| = t_0` at
# :math:`t = T`. The final fields on rank 0 (``fields_final.npz``: cell values and centres)
# give the mean over the strip's cells. The damage stays in :math:`[\zeta_*, 1]`.

fields = None
if comm.rank == 0:
    with np.load(out / "fields_final.npz") as data:
        fields = {key: data[key] for key in data.files}
fields = comm.bcast(fields, root=0)
xy, von_mises = fields["von_mises_coords"], fields["von_mises"].ravel()
strip = (xy[:, 0] > 2.5) & (xy[:, 0] < 3.5)
deviation = abs(von_mises[strip].mean() / t0 - 1)
tolerance = 0.02
verdict = "PASS" if deviation <= tolerance else "FAIL"
zeta = fields["zeta"].ravel()  # one value per vertex
zeta_star = summary["parameters"]["zeta_star"]
outside = max(0.0, zeta_star - zeta.min(), zeta.max() - 1.0)
bound = "PASS" if outside <= 1e-12 else "FAIL"
if comm.rank == 0:
    print(f"mean von Mises stress far from the notch: {von_mises[strip].mean():.3f} "
          f"(traction {t0:g}); at the notch root: {von_mises.max():.1f}")
    print(f"PHYSICS_CHECK far_field_stress {deviation:.3e} {tolerance:.0e} {verdict}")
    print(f"PHYSICS_CHECK zeta_in_bounds {outside:.3e} 1e-12 {bound}")
assert verdict == "PASS" and bound == "PASS", (deviation, outside)

# %%
# The reactions of the two symmetry planes (``contact_force_x`` in ``history.csv``: the
# resultant of the bilateral contact, a contact output of every model) balance the load
# :math:`t_0 \cdot 1` on the end :math:`x = 4` (height 1) at the last step: the plate is at
# rest.

run = dd.read_run(out)
resultant = run.history["contact_force_x"][-1]
balance = abs(resultant / (t0 * 1.0) + 1)
if comm.rank == 0:
    print(f"contact resultant at T: {resultant:.10g} (load: {-t0:g})")
    print(f"PHYSICS_CHECK contact_balance {balance:.3e} 1e-08 "
          f"{'PASS' if balance <= 1e-8 else 'FAIL'}")
assert balance <= 1e-8, balance

# %%
# Figure
# ------
# The damage :math:`1 - \zeta` at :math:`t = T` on the quarter plate: it is largest at the
# root of the notch, :math:`(0, 0.7)`, and decays to the nearly uniform value of the bar.

if comm.rank == 0:
    import matplotlib.pyplot as plt
    from matplotlib.tri import Triangulation

    xz = fields["zeta_coords"]
    fig, ax = plt.subplots(figsize=(8, 2.6), constrained_layout=True)
    tri = Triangulation(xz[:, 0], xz[:, 1])
    centre = np.column_stack([xz[tri.triangles, 0].mean(1), xz[tri.triangles, 1].mean(1)])
    tri.set_mask(np.hypot(centre[:, 0], centre[:, 1] - 1) < 0.3)  # the notch is not material
    shade = ax.tripcolor(tri, 1 - zeta, shading="gouraud", cmap="magma_r")
    fig.colorbar(shade, ax=ax, label=r"damage $1 - \zeta$")
    ax.set_aspect("equal")
    ax.set_xlabel("$x$")
    ax.set_ylabel("$y$")
    ax.set_title(rf"quarter plate at $t = T$ (traction {t0:g} at $x = 4$)")
    fig.savefig(out / "damage.png", dpi=120)
