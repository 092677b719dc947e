r"""
A parameter sweep, interrupted and resumed
==========================================

How does the damage at the end of a loading depend on the damage rate :math:`\lambda_u^+` and
the diffusion :math:`\kappa`? :func:`damage_dolfinx.sweep` runs one problem at every point of a
grid of parameter values (the product of the value lists), each point a normal run folder
``point_<i>``, and gathers every point's final scalars into ``sweep.csv`` and a plot. On
several ranks the points are shared out, each run serially on its rank. A sweep that stops
(a limit, a signal, a crash) is resumed by running it again: finished points are kept.

The same from the command line, for a catalogue example::

    damage-dolfinx sweep 2.1-ex1 --set kappa=0.01,0.1,1 --set lam_u_plus=500,1000 --out DIR

The model is the quasistatic elastic model with damage (``"2.1"``) of the other demos:

.. math::

   -\operatorname{div} \bigl(\eta_*(\zeta)\, \mathcal{B}\,\varepsilon(u)\bigr) = 0,
   \qquad
   \dot\zeta - \kappa \Delta \zeta = \lambda_D \frac{1 - \zeta}{\eta_*(\zeta)}
   - \frac{\lambda_u^+}{2} \Psi(\varepsilon^+) - \frac{\lambda_u^-}{2} \Psi(\varepsilon^-).

What to take away: how to sweep, resume and read a sweep, and a trend to expect: a larger
damage rate gives more damage, a smaller :math:`\min\zeta`.
"""

# %%
# Mesh and model
# --------------
# The strip :math:`(0, 2) \times (0, 0.5)` as a mesh family (level :math:`n`: :math:`4n \times
# n` squares), clamped at :math:`x = 0`, pulled at :math:`x = 2` by :math:`(200\,t, 0)` to
# :math:`T = 0.5` in 10 steps. A mesh family (or a file) lets each rank build its own serial
# mesh for its points.

import json
import os
from pathlib import Path

import numpy as np
import ufl
from mpi4py import MPI

import damage_dolfinx as dd
from damage_dolfinx.geometries.rectangle import rectangle, side

comm = MPI.COMM_WORLD
out = Path(os.environ.get("DAMAGE_DOLFINX_DEMO_OUT", "results")) / "parameter_sweep"


def strip(comm, n):
    return rectangle(comm, (0.0, 0.0), (2.0, 0.5), 4 * n, n, {1: side(0, 0.0), 2: side(0, 2.0)})


problem = dd.Problem(
    model="2.1", mesh=strip, n=3, T=0.5, k=0.05, name="strip-sweep",
    boundaries={"clamped": 1, "traction": 2},
    traction=lambda x, t: ufl.as_vector((200.0 * t, 0.0)),
    params={"E": 1e4, "lam_u_minus": 0.0, "stop_at_zeta_star": False})
grid = {"kappa": [0.01, 0.1, 1.0], "lam_u_plus": [500.0, 1000.0]}

# %%
# Run, interrupted
# ----------------
# A clean start (a sweep folder keeps its finished points, so the demo removes its own
# folder of a previous run first), then the first 3 of the 6 points only (``max_points=3``): as if the
# sweep had been stopped.

if comm.rank == 0 and out.exists():
    import shutil
    shutil.rmtree(out)
comm.Barrier()
first = dd.sweep(problem, out, grid, max_points=3, figures=False, progress=False)
finished = None
if comm.rank == 0:
    finished = {i: (out / f"point_{i}" / "summary.json").read_text() for i in range(3)}
    print(f"after the interruption: {first['completed']} of {first['points']} points, "
          f"pending {first['pending']}")

# %%
# Resume
# ------
# The same call again runs the 3 pending points and keeps the 3 finished ones untouched.

summary = dd.sweep(problem, out, grid, plot="zeta_min", figures=False, progress=False)
table = None
if comm.rank == 0:
    kept = all((out / f"point_{i}" / "summary.json").read_text() == text
               for i, text in finished.items())
    mapping = json.loads((out / "points.json").read_text())
    for point in mapping["points"]:
        print(f"{point['folder']}: {point['values']}")
    table = np.genfromtxt(out / "sweep.csv", delimiter=",", names=True, dtype=None,
                          encoding="utf-8")
    print(f"resumed: {summary['completed']} of {summary['points']} points, finished ones "
          f"kept: {kept}; table sweep.csv, plot sweep.png")
table = comm.bcast(table, root=0)

# %%
# Physics check
# -------------
# For every :math:`\kappa`, doubling :math:`\lambda_u^+` lowers :math:`\min \zeta`: the check
# is the largest increase of :math:`\min\zeta` from :math:`\lambda_u^+ = 500` to 1000
# (none expected).

rises = []
for kappa in grid["kappa"]:
    row = table[np.isclose(table["kappa"], kappa)]
    order = np.argsort(row["lam_u_plus"])
    rises.append(float(np.max(np.diff(row["zeta_min"][order]))))
value = max(max(rises), 0.0)
verdict = "PASS" if value <= 0.0 and summary["completed"] == 6 else "FAIL"
if comm.rank == 0:
    print(f"PHYSICS_CHECK monotone_in_lam_u {value:.3e} 0e+00 {verdict}")
assert verdict == "PASS", (rises, summary)

# %%
# Figure
# ------
# The plot the sweep wrote: :math:`\min\zeta` at :math:`T` against :math:`\kappa`, one line per
# :math:`\lambda_u^+`. More diffusion spreads the damage out, so :math:`\min\zeta` rises
# with :math:`\kappa`; the damage rate sets its level.

if comm.rank == 0:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.6), constrained_layout=True)
    ax.imshow(plt.imread(out / "sweep.png"))
    ax.set_axis_off()
