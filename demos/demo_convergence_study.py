r"""
Convergence study of your own problem
=====================================

How fast does a run approach the exact solution as the mesh size :math:`h` and the time step
:math:`k` shrink? :func:`damage_dolfinx.converge` answers with a reference run on a fine mesh
and a small step, and coarse runs on the levels :math:`(n, k)` of a *mesh family*, all
advancing together; at every common time level each coarse solution is transferred exactly to
the nested reference mesh and measured there:

.. math::

   e(h, k) = \max_{t_n} \Bigl(\|u_{\mathrm{ref}} - u_{hk}\|_V
   + \|\zeta_{\mathrm{ref}} - \zeta_{hk}\|_{L^2}\Bigr)(t_n),
   \qquad \|v\|_V = \|\varepsilon(v)\|_{L^2}.

Piecewise linear elements and the implicit Euler steps of the models are of first order:
:math:`e \approx C (h + k)`.

What to take away: how to write a mesh family ``(comm, n) -> mesh`` of nested meshes, run the
study, and read the fitted rate.
"""

# %%
# Mesh family
# -----------
# The strip :math:`(0, 2) \times (0, 0.5)` with :math:`4n \times n` squares: the meshes of
# levels :math:`n` and :math:`2n` are nested, as the study requires. Tags: 1 at :math:`x = 0`
# (clamped), 2 at :math:`x = 2` (loaded).

import os
from pathlib import Path

import numpy as np
import ufl
from mpi4py import MPI

import damage_dolfinx as dd
from damage_dolfinx.geometries.rectangle import rectangle, side

comm = MPI.COMM_WORLD
out = Path(os.environ.get("DAMAGE_DOLFINX_DEMO_OUT", "results")) / "convergence_study"


def strip(comm, n):
    return rectangle(comm, (0.0, 0.0), (2.0, 0.5), 4 * n, n, {1: side(0, 0.0), 2: side(0, 2.0)})


# %%
# Model
# -----
# The quasistatic elastic model ``"2.1"``, pulled and sheared at :math:`x = 2` by
# :math:`(100\,t, -5\,t)` up to :math:`T = 0.5`, with damage in tension and compression
# (:math:`\lambda_u^\pm = 10^4`) and diffusion :math:`\kappa = 0.1`.

problem = dd.Problem(
    model="2.1", mesh=strip, n=4, T=0.5, name="strip",
    boundaries={"clamped": 1, "traction": 2},
    traction=lambda x, t: ufl.as_vector((100.0 * t, -5.0 * t)),
    params={"E": 1e4, "kappa": 0.1, "lam_u_plus": 1e4, "lam_u_minus": 1e4,
            "stop_at_zeta_star": False})

# %%
# Run the study
# -------------
# Coarse levels :math:`n = 2, 4, 8` and :math:`k = 0.1, 0.05, 0.025` against the reference
# :math:`n = 16`, :math:`k = 0.0125`. On several ranks the coarse runs are shared out among
# them. The study writes ``errors.csv``, ``errors.md``, ``convergence.png`` and
# ``summary.json``.

study = dd.converge(problem, out, n=[2, 4, 8], k=[0.1, 0.05, 0.025], ref_n=16, ref_k=0.0125,
                    progress=False)

# %%
# Physics check
# -------------
# The rate fitted to all nine cells, :math:`e \approx C (h + k)^p`, is the order of the
# method: :math:`p = 1` within 0.3.

rate = study["rates"]["h_plus_k_all"]
deviation = abs(rate - 1.0)
tolerance = 0.3
verdict = "PASS" if deviation <= tolerance else "FAIL"
if comm.rank == 0:
    print(f"error: {study['error_definition']}")
    print(f"fitted rate in h + k: {rate:.3f}; on the diagonal (n, k) pairs: "
          f"{study['rates']['h_plus_k_diagonal']:.3f}")
    print(f"PHYSICS_CHECK convergence_rate {deviation:.3e} {tolerance:.0e} {verdict}")
assert verdict == "PASS", rate

# %%
# Figure
# ------
# The error of every cell against :math:`h + k`, one line per time step, and the fitted
# slope. For the smallest :math:`k` the error falls with :math:`h` at the fitted rate; for
# the largest, the time error limits it.

if comm.rank == 0:
    import matplotlib.pyplot as plt

    rows = study["errors"]
    fig, ax = plt.subplots(figsize=(6.4, 4.4), constrained_layout=True)
    for k in sorted({r["k"] for r in rows}, reverse=True):
        sel = sorted((r for r in rows if r["k"] == k), key=lambda r: r["h_plus_k"])
        ax.loglog([r["h_plus_k"] for r in sel], [r["error"] for r in sel], "o-",
                  label=f"$k = {k:g}$")
    hk = np.array([r["h_plus_k"] for r in rows])
    err = np.array([r["error"] for r in rows])
    c = np.exp(np.mean(np.log(err) - rate * np.log(hk)))
    xs = np.array([hk.min(), hk.max()])
    ax.loglog(xs, c * xs**rate, "k--", label=f"fit: rate {rate:.2f}")
    ax.set_xlabel("$h + k$")
    ax.set_ylabel(r"$e(h, k)$")
    ax.legend()
