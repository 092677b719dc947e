r"""
Coulomb friction with normal compliance: stick and slip
=======================================================

A model of your own with a friction bound that depends on the solution: a dynamic
Kelvin-Voigt block with damage on a compliant foundation, with Coulomb friction
:math:`g = \mu\, p_\nu(u_{n-1})` (``blocks.coulomb_friction_bound``). At each step
:math:`t_{n-1} \to t_n`:

1. the damage step (obstacle inclusion, explicit source);
2. the velocity, a Tresca-type inequality with the bound of the previous step's pressure:

.. math::

   \rho\Bigl(\frac{v_n - v_{n-1}}{k}, w - v_n\Bigr) + (\mathcal{A}\varepsilon(v_n), \varepsilon(w - v_n))
   + (\zeta_{n-1}\Phi_L(\mathcal{B}\varepsilon(u_{n-1})), \varepsilon(w - v_n))
   + \int_{\Gamma_C} p_\nu(u_{n-1}) (w - v_n)\cdot\nu
   + j(w) - j(v_n) \ge L_n(w - v_n),\quad j(w) = \int_{\Gamma_C} \mu p_\nu(u_{n-1}) |w_\tau|;

3. :math:`u_n = u_{n-1} + k v_n`.

The block :math:`(0, 1) \times (0, 0.25)` is pressed by a traction :math:`q` and pulled by a
shear traction :math:`f_x` on its top; the foundation starts preloaded (gap :math:`-q/c_\nu`),
so the normal force is :math:`N = q` from the start. The friction solver evaluates the bound at
the contact nodes at the start of every solve. The physics check is the momentum balance: the
block sticks for :math:`f_x < \mu q` (its momentum stays at zero) and slides for
:math:`f_x > \mu q` with :math:`dP_x/dt = F_x - \mu N`.
"""

# %%
# The model
# ---------
import dataclasses
import os
import sys
from pathlib import Path

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

import damage_dolfinx as dd
from damage_dolfinx import blocks as b
from damage_dolfinx.geometries.rectangle import rectangle, side


class CoulombKelvinVoigt(dd.Model):
    """Dynamic Kelvin-Voigt body with damage, normal compliance and Coulomb friction."""

    id = "kv-coulomb"
    title = "dynamic Kelvin-Voigt body, normal compliance with Coulomb friction"
    contact_roles = ("coulomb",)
    dynamic = True
    stability_limit = "explicit elastic and contact terms (eigenvalue estimate)"
    checkpoint_fields = ("u", "zeta", "v")
    history_columns = ("momentum_x", "normal_force", "friction_its")
    old_state = (("u", "u_old"), ("v", "v_old"), ("zeta", "zeta_old"))
    update = ("u", "u_old", "v")

    @classmethod
    def defaults(cls):
        p = dd.model_defaults("2.2")
        return dataclasses.replace(p, E=1000.0, extra={
            "m_visc": 10.0, "rho": 1.0, "c_nu": 1e3, "mu": 0.3, "q": 10.0, "fx": 4.0,
            "eps_reg": 1e-9, "bound": "coulomb", "preload": 1.0})

    def __init__(self, data):
        super().__init__(data)
        p, x, msh = self.params, self.params.extra, self.mesh
        V, Z = b.vector_p1(msh), b.scalar_p1(msh)
        self.u, self.u_old, self.v, self.v_old = (fem.Function(V, name=s)
                                                  for s in ("u", "u_old", "v", "v_old"))
        self.zeta, self.zeta_old = fem.Function(Z, name="zeta"), fem.Function(Z, name="zeta_old")
        self.damage = self.obstacle_damage_step()                                  # (1)
        k, rho = data.time.k, x["rho"]
        tags = data.geometry.facet_tags
        ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
        self.dsC, self.nu = ds(3), ufl.FacetNormal(msh)
        self.gap = -x["preload"] * x["q"] / x["c_nu"]    # preloaded: p_nu(0) = preload q
        p_old = b.normal_compliance_pressure(self.u_old, self.nu, x["c_nu"], self.gap)
        dv, w = ufl.TrialFunction(V), ufl.TestFunction(V)
        a = (rho / k * ufl.dot(dv, w) * ufl.dx
             + ufl.inner(b.viscous_stress(dv, p.E, p.nu, x["m_visc"]), b.eps(w)) * ufl.dx)
        l = (rho / k * ufl.dot(self.v_old, w) * ufl.dx
             - ufl.inner(b.damaged_elastic_stress(self.u_old, self.zeta_old, p.E, p.nu,
                                                  p.L_trunc), b.eps(w)) * ufl.dx
             - p_old * ufl.dot(w, self.nu) * self.dsC
             + b.load(w, None, self.loads()[1], ds(2)))
        if x["bound"] == "coulomb":                      # g = mu p_nu(u_{n-1}): of the state
            g = b.coulomb_friction_bound(x["mu"], self.u_old, self.nu, x["c_nu"], self.gap)
        else:                                            # the same value, a constant bound
            g = fem.Constant(msh, x["mu"] * x["q"])
        self.friction_problem = b.FrictionProblem(self.v, a, l, [], g, self.dsC, self.context)
        self.friction = b.friction_solver("newton", self.friction_problem, x["eps_reg"],
                                          1.0, 100.0)                             # (2)
        self._k_max = b.estimate_k_max(V, p.E, p.nu, rho, x["m_visc"], x["c_nu"], self.dsC,
                                       normal=self.nu)
        self._momentum = fem.form(rho * self.v[0] * ufl.dx)
        self._normal = fem.form(self.contact_pressure() * self.dsC)
        Q = b.scalar_dg0(msh)
        self.von_mises = fem.Function(Q, name="von_mises")
        sigma = b.kelvin_voigt_stress(self.v, self.u, self.zeta, p.E, p.nu, x["m_visc"],
                                      p.L_trunc)
        self._vm = b.expression(b.von_mises(sigma), Q)
        self.output_fields = [self.u, self.v, self.zeta, self.von_mises]

    def mesh_k_max(self):
        return self._k_max

    def contact_pressure(self):
        x = self.params.extra
        return b.normal_compliance_pressure(self.u, self.nu, x["c_nu"], self.gap)

    def scheme(self):
        return (dd.SubStep("damage", "snes-vi", "damage_", self.damage.solve, ("damage_its",)),
                dd.SubStep("friction", "newton", "friction_", self.friction.solve,
                           ("snes_its", "friction_its")))

    def scalars(self):
        total = lambda f: self.comm.allreduce(fem.assemble_scalar(f), op=MPI.SUM)  # noqa: E731
        return {**super().scalars(), "momentum_x": total(self._momentum),
                "normal_force": total(self._normal)}

    def update_output(self):
        b.interpolate(self.von_mises, self._vm)


def block(comm, n):
    return rectangle(comm, (0.0, 0.0), (1.0, 0.25), 4 * n, n,
                     {2: side(1, 0.25), 3: side(1, 0.0)})


def problem(fx, bound="coulomb", n=4, T=1.0, k=0.005, preload=1.0, ramp=0.0):
    """f_x and the bound; ``preload`` the foundation's initial pressure (times q), ``ramp``
    the time over which q rises to its value (0: at once)."""
    q = CoulombKelvinVoigt.defaults().extra["q"]

    def rise(t):
        return 1.0 if ramp == 0 else ufl.min_value(t / ramp, 1.0)
    return dd.Problem(model=CoulombKelvinVoigt, mesh=block, n=n, T=T, k=k,
                      name=f"coulomb-{bound}-fx{fx:g}",
                      boundaries={"traction": 2, "coulomb": 3},
                      params={"fx": fx, "bound": bound, "preload": preload},
                      traction=lambda x, t: ufl.as_vector((fx, -q * rise(t))))


comm = MPI.COMM_WORLD
out = Path(os.environ.get("DAMAGE_DOLFINX_DEMO_OUT", ".")) / "coulomb"
params = CoulombKelvinVoigt.defaults().extra
mu, q = params["mu"], params["q"]


def slope(folder):
    """dP_x/dt by least squares over the second half of the run, and N there (mean)."""
    import csv
    with open(folder / "history.csv") as f:
        rows = list(csv.DictReader(f))
    t = np.array([float(r["t"]) for r in rows])
    P = np.array([float(r["momentum_x"]) for r in rows])
    N = np.array([float(r["normal_force"]) for r in rows])
    half = t >= 0.5 * t[-1]
    return np.polyfit(t[half], P[half], 1)[0], N[half].mean(), t, P


# %%
# Stick and slip
# --------------
# Below :math:`\mu q = 3` the block sticks, above it slides; F_x = f_x (top of length 1).

if __name__ == "__main__" or "DAMAGE_DOLFINX_DEMO_OUT" in os.environ:
    results = {}
    for fx in (2.0, 4.0):
        folder = out / f"fx{fx:g}"
        summary = dd.run(problem(fx), folder, progress=False, figures=False, overwrite=True)
        s, N, t, P = slope(folder)
        expected = max(fx - mu * N, 0.0)
        results[fx] = (s, N, expected, t, P)
        error = abs(s - expected) / (mu * q)
        if comm.rank == 0:
            print(f"f_x = {fx:g} ({'slip' if fx > mu * q else 'stick'}): dP/dt = {s:.6g}, "
                  f"F_x - mu N = {fx - mu * N:.6g} (N = {N:.6g}); {summary['status']}")
            print(f"PHYSICS_CHECK momentum_balance_fx{fx:g} {error:.3e} 2e-2 "
                  f"{'PASS' if error <= 2e-2 else 'FAIL'}")
        assert error <= 2e-2
    if comm.rank == 0:
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(5.5, 3.4))
        for fx, (s, N, expected, t, P) in results.items():
            ax.plot(t, P, label=f"$f_x = {fx:g}$")
            ax.plot(t, expected * (t - 0.0), ":", color="0.4")
        ax.set_xlabel("time $t$")
        ax.set_ylabel(r"momentum $P_x = \int \rho v_x$")
        ax.set_title(r"stick ($f_x < \mu q$) and slip: slope $F_x - \mu N$ (dotted)")
        ax.legend()
        fig.tight_layout()
        fig.savefig(out / "momentum.png", dpi=120)
