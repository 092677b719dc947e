r"""
Your own damage law, with and without irreversibility
=====================================================

Every model advances the damage :math:`\zeta` by the same step, whatever the law: find
:math:`\zeta_n` with

.. math::

   (\zeta_n - \zeta_{n-1}, \xi) + k \kappa (\nabla\zeta_n, \nabla\xi)
   = k\, \bigl(\phi(\varepsilon(u_{n-1}), \zeta_{n-1}), \xi\bigr)
   \quad \forall \xi,

and the *damage law* :math:`\phi` is yours to choose: any UFL expression of the strain, the
damage and the run's parameters, wrapped in :class:`damage_dolfinx.DamageLaw`. Here a law that
damages only beyond a threshold strain :math:`\varepsilon_0` and heals at the rate
:math:`\lambda_h` otherwise:

.. math::

   \phi(\varepsilon, \zeta) = \lambda_h (1 - \zeta)
   - \lambda \bigl(|\varepsilon|^2 - \varepsilon_0^2\bigr)_+ .

With ``irreversible=True`` the damage step also asks :math:`\zeta_n \le \zeta_{n-1}`: the
material never heals, whatever the law says.

What to take away: how to write a law and pass its own data (``params`` names the model does
not know go to the law), and what irreversibility changes when the load is removed.
"""

# %%
# Mesh
# ----
# A strip :math:`(0, 2) \times (0, 0.5)`, 16 x 4 squares cut in two triangles, clamped at
# :math:`x = 0` (tag 1), loaded at :math:`x = 2` (tag 2).

import os
from pathlib import Path

import numpy as np
import ufl
from mpi4py import MPI

import damage_dolfinx as dd
from damage_dolfinx.geometries.rectangle import rectangle, side

comm = MPI.COMM_WORLD
out = Path(os.environ.get("DAMAGE_DOLFINX_DEMO_OUT", "results")) / "own_damage_law"


def strip(comm, n):
    return rectangle(comm, (0.0, 0.0), (2.0, 0.5), 4 * n, n, {1: side(0, 0.0), 2: side(0, 2.0)})


# %%
# Model
# -----
# The law reads its data from ``p.extra``. The quasistatic elastic model ``"2.1"`` with a pull
# that rises to 200 at :math:`t = 0.5` and is removed at once: the strain drops below the
# threshold and, without irreversibility, the healing term brings :math:`\zeta` back towards 1.


def threshold_law(eps, zeta, p):
    x = p.extra
    return x["lam_h"] * (1 - zeta) - x["lam"] * ufl.max_value(
        ufl.inner(eps, eps) - x["eps0"] ** 2, 0.0)


law = dd.DamageLaw(threshold_law, name="threshold with healing")


def pull(x, t):
    return ufl.as_vector((ufl.conditional(ufl.le(t, 0.5 + 1e-9), 400.0 * t, 0.0), 0.0))


def problem(irreversible):
    return dd.Problem(
        model="2.1", mesh=strip, n=4, T=1.0, k=0.05, traction=pull, damage_law=law,
        irreversible=irreversible, name=f"own-law-irreversible-{irreversible}",
        boundaries={"clamped": 1, "traction": 2},
        params={"E": 1e4, "kappa": 0.01, "stop_at_zeta_star": False,
                "lam": 3000.0, "eps0": 0.01, "lam_h": 2.0})


# %%
# Run
# ---
# The same problem twice, without and with irreversibility.

histories = {}
for irreversible in (False, True):
    folder = out / ("irreversible" if irreversible else "reversible")
    summary = dd.run(problem(irreversible), folder, overwrite=True, progress=False)
    history = None
    if comm.rank == 0:
        history = np.genfromtxt(folder / "history.csv", delimiter=",", names=True)
    histories[irreversible] = comm.bcast(history, root=0)
    if comm.rank == 0:
        print(f"irreversible = {irreversible}: {summary['status']}, {summary['steps_done']} "
              f"steps on {comm.size} rank(s), final min zeta = "
              f"{summary['final']['zeta_min']:.4f}")

# %%
# Physics checks
# --------------
# * Irreversible: the smallest damage value never increases,
#   :math:`\max_n (\min\zeta_n - \min\zeta_{n-1}) \le 0` (the step's bound holds at every node;
#   the history shows its minimum), and after the load is removed :math:`\zeta` stays where it
#   was.
# * Reversible: after the unloading the law heals: :math:`\min\zeta` rises again, by more than
#   0.01 up to :math:`T`.

t = histories[True]["t"]
zmin_irr, zmin_rev = histories[True]["zeta_min"], histories[False]["zeta_min"]
unloaded = t > 0.5 + 1e-9
rise_irreversible = max(float(np.max(np.diff(zmin_irr))), 0.0)
healing = float(zmin_rev[-1] - zmin_rev[unloaded][0])
checks = [("irreversible_never_heals", rise_irreversible, 1e-12),
          ("reversible_heals", max(0.01 - healing, 0.0), 0.0)]
if comm.rank == 0:
    print(f"min zeta at unloading: {zmin_rev[unloaded][0]:.4f}; at T: reversible "
          f"{zmin_rev[-1]:.4f}, irreversible {zmin_irr[-1]:.4f}")
    for name, value, tol in checks:
        print(f"PHYSICS_CHECK {name} {value:.3e} {tol:.0e} {'PASS' if value <= tol else 'FAIL'}")
assert all(value <= tol for _, value, tol in checks), checks

# %%
# Figure
# ------
# Both runs agree while the load rises; once it is removed the reversible material heals and
# the irreversible one keeps its damage.

if comm.rank == 0:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 3.8), constrained_layout=True)
    ax.plot(t, zmin_rev, "o-", ms=3, label="reversible")
    ax.plot(t, zmin_irr, "s-", ms=3, label="irreversible")
    ax.axvline(0.5, color="k", ls=":", lw=1, label="load removed")
    ax.set_xlabel("time $t$")
    ax.set_ylabel(r"$\min \zeta$")
    ax.legend()
    fig.savefig(out / "healing.png", dpi=120)
