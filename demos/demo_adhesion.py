r"""
Adhesion: a bonded block pulled off its foundation
==================================================

A model of your own with a field that lives on the contact boundary :math:`\Gamma_C` only: the
bonding field :math:`\beta \in [0, 1]` of Frémond and Raous (1 bonded, 0 debonded), with its
own evolution law, on a quasistatic Kelvin-Voigt body with damage (the body of 2.2). On
:math:`\Gamma_C`, with :math:`u_\nu = u\cdot\nu` (separation is :math:`u_\nu < 0`), the
truncated separation :math:`R(u_\nu) = \min((-u_\nu)_+, L)` and normal compliance
:math:`p_\nu(r) = c_\nu r_+` in compression,

.. math::

   -\sigma_\nu = p_\nu(u_\nu) - \gamma_\nu \beta^2 R(u_\nu),
   \qquad \dot\beta = -\bigl(\gamma_\nu \beta R(u_\nu)^2 - \varepsilon_a\bigr)_+,
   \qquad \beta(0) = \beta_0,                                                        \tag{A1}

the adhesive traction :math:`\gamma_\nu\beta^2 R` resists separation, the bonds break as the
adhesive is stretched, and the rate :math:`\varepsilon_a` is a threshold of the rupture. At
each step :math:`t_{n-1} \to t_n`:

1. the damage step of 2.2 (obstacle inclusion in :math:`[\zeta_*, 1]`, explicit source of
   :math:`u_{n-1}`);
2. the bonding field at each node :math:`x_i` of :math:`\Gamma_C`, backward Euler with the
   separation of the previous step, :math:`R_i = R(u_{n-1}(x_i)\cdot\nu_i)`:

   .. math::

      \beta_n = \beta_{n-1} - k\bigl(\gamma_\nu\beta_n R_i^2 - \varepsilon_a\bigr)_+
      \iff \beta_n = \begin{cases}
        \dfrac{\beta_{n-1} + k\varepsilon_a}{1 + k\gamma_\nu R_i^2} &
        \gamma_\nu\beta_{n-1}R_i^2 > \varepsilon_a,\\
        \beta_{n-1} & \text{otherwise,}\end{cases}                                  \tag{A2}

   so that :math:`0 \le \beta_n \le \beta_{n-1}` for every :math:`k` (no bound is imposed:
   the state check verifies :math:`\beta \in [0, 1]` after every step);
3. the velocity :math:`v_n`, semismooth Newton on

   .. math::

      (\mathcal{A}\varepsilon(v_n), \varepsilon(w))
      + (\zeta_{n-1}\Phi_L(\mathcal{B}\varepsilon(u_{n-1})), \varepsilon(w))
      + \int_{\Gamma_C} \bigl(p_\nu(r_n) - \gamma_\nu\beta_n^2 R(r_n)\bigr)\, w\cdot\nu
      = L_n(w), \qquad r_n = (u_{n-1} + k v_n)\cdot\nu;                              \tag{A3}

4. :math:`u_n = u_{n-1} + k v_n`.                                                      (A4)

**Where** :math:`\beta` **lives.** DOLFINx assembles no form of a field on a boundary mesh
together with fields of the body, so :math:`\beta` is a P1 Function of the body's mesh of
which only the dofs at the nodes of :math:`\Gamma_C` are unknowns: (A2) updates those dofs
alone, the others hold 0 and are never read (the trace of a P1 field on a facet depends on the
facet's nodes only, so (A3) sees exactly the nodal values on :math:`\Gamma_C`). The nodal
normal :math:`\nu_i` is the length-weighted mean of the facet normals at the node. :math:`\beta`
is part of the declared state: it is checkpointed (a restart is exact), its bounds
:math:`[0, 1]` are declared (``state_bounds``), and it is written with the fields.

The block :math:`(0, 1) \times (0, 0.25)` is bonded along its bottom (:math:`\Gamma_C`), held
horizontally by a roller on its left side and pulled up by a traction :math:`(0, 3 q t x^2)` on
its top: the total pull is :math:`q t`, stronger at the right end, so the bonds break there
first while the left end is pressed into the foundation (normal compliance) by the moment. A
debonding front runs from the right to the left.

The physics checks: the foundation's traction balances the pull, :math:`\int_{\Gamma_C}
(p_\nu - \gamma_\nu\beta^2R)\,\nu_y = q t` (the roller takes no vertical force); and at
every node of :math:`\Gamma_C` the computed :math:`\beta` against the closed-form solution of
its ODE (A1) for the computed separation history (:math:`R` constant on each step, as (A2)
sees it: :math:`\beta` relaxes exponentially towards :math:`\beta_{eq} = \varepsilon_a/(\gamma_\nu
R^2)` while it lies above it, and stays put below). With :math:`x = k\gamma_\nu R^2`, a step of
(A2) multiplies the distance to :math:`\beta_{eq}` by :math:`1/(1+x)`, the ODE by
:math:`e^{-x}`, and :math:`0 \le 1/(1+x) - e^{-x} \le x^2/2`; both maps are monotone with
Lipschitz constant 1. So at every node :math:`0 \le \beta_n - \beta(t_n) \le \sum_m
\tfrac{1}{2}x_m^2(\beta_{m-1} - \beta_{eq,m})_+`: backward Euler lags the closed form, by at
most that sum. A wrong law (power of :math:`\beta`, sign or truncation of :math:`R`, the rate's
threshold) or explicit Euler (which leads the closed form) fails it.
"""

# %%
# The model
# ---------
import dataclasses
import os
from pathlib import Path

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

import damage_dolfinx as dd
from damage_dolfinx import blocks as b
from damage_dolfinx.geometries.rectangle import rectangle, side

GAMMA_C = 3


class AdhesiveKelvinVoigt(dd.Model):
    """Kelvin-Voigt body with damage bonded to a foundation: adhesion (A1)-(A4) on Gamma_C."""

    id = "kv-adhesion"
    title = "quasistatic Kelvin-Voigt body with damage, adhesive contact"
    contact_roles = ("adhesion",)
    extra_roles = {"roller": 4}
    stability_limit = "explicit elastic term: k <= 2/m_visc"
    checkpoint_fields = ("u", "zeta", "v", "beta")
    state_bounds = {"beta": (0.0, 1.0)}
    history_columns = ("adhesive_force", "bonded", "beta_min", "beta_max")
    update = ("u", "u_old", "v")                                       # (A4)
    contact_quadrature_degree = 4                 # one rule for (A3) and the resultant

    @classmethod
    def defaults(cls):
        p = dd.model_defaults("2.2")
        return dataclasses.replace(p, E=1000.0, extra={
            "m_visc": 10.0, "c_nu": 1e4, "gamma_nu": 1e3, "eps_a": 0.01, "L_adh": 1.0,
            "beta0": 1.0})

    @classmethod
    def k_max(cls, params):
        return dd.model_class("2.2").k_max(params)  # the same explicit elastic term

    def __init__(self, data):
        super().__init__(data)
        p, x, msh = self.params, self.params.extra, self.mesh
        V, Z = b.vector_p1(msh), b.scalar_p1(msh)
        self.u, self.u_old, self.v = (fem.Function(V, name=s) for s in ("u", "u_old", "v"))
        self.zeta, self.zeta_old = fem.Function(Z, name="zeta"), fem.Function(Z, name="zeta_old")
        self.beta = fem.Function(Z, name="beta")
        self.k = data.time.k
        self.damage = self.obstacle_damage_step()                      # (1)
        tags = data.geometry.facet_tags
        ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
        self.dsC = ds(GAMMA_C, metadata={"quadrature_degree": self.contact_quadrature_degree})
        self.nu = ufl.FacetNormal(msh)
        self._gamma_c_nodes(Z, V, tags)
        w, v = ufl.TestFunction(V), self.v
        F = (ufl.inner(b.viscous_stress(v, p.E, p.nu, x["m_visc"]), b.eps(w)) * ufl.dx
             + ufl.inner(b.damaged_elastic_stress(self.u_old, self.zeta_old, p.E, p.nu,
                                                  p.L_trunc), b.eps(w)) * ufl.dx
             + self.traction(self.u_old + self.k * v) * ufl.dot(w, self.nu) * self.dsC)  # (A3)
        f_B, f_N = self.loads()
        F = F - b.load(w, f_B, f_N, ds(2))
        bcs = [b.clamped(V, tags, 1)] + b.bilateral(V, tags, 4)
        self.mech = b.NonlinearSolver(F, self.v, bcs, "mech_", self.context)
        self._bonded = fem.form(self.beta * self.dsC)
        self._length = msh.comm.allreduce(fem.assemble_scalar(fem.form(1.0 * self.dsC)),
                                          op=MPI.SUM)
        Q = b.scalar_dg0(msh)
        self.von_mises = fem.Function(Q, name="von_mises")
        sigma = b.kelvin_voigt_stress(v, self.u, self.zeta, p.E, p.nu, x["m_visc"], p.L_trunc)
        self._vm = b.expression(b.von_mises(sigma), Q)
        self.output_fields = [self.u, self.v, self.zeta, self.beta, self.von_mises]
        # errors of a convergence study: beta in the L2 norm of Gamma_C, where it lives
        self.error_components = [("u", self.u, "V"), ("zeta", self.zeta, "L2"),
                                 ("beta", self.beta, "L2_GammaC")]

    def _gamma_c_nodes(self, Z, V, tags):
        """The local dofs of beta at the nodes of Gamma_C (owned and ghost) and their nodal
        normals (length-weighted facet normals, summed over the ranks)."""
        fdim = self.mesh.topology.dim - 1
        self.mesh.topology.create_connectivity(fdim, fdim + 1)
        facets = tags.indices[tags.values == GAMMA_C]
        self.nodes = fem.locate_dofs_topological(Z, fdim, facets)
        if not np.allclose(V.tabulate_dof_coordinates(), Z.tabulate_dof_coordinates()):
            raise RuntimeError("the vector and scalar P1 spaces number their nodes differently")
        xi, normal = ufl.TestFunction(Z), []
        for i in range(self.mesh.geometry.dim):
            f = fem.Function(Z)
            fem.assemble_vector(f.x.array, fem.form(self.nu[i] * xi * ufl.ds(
                domain=self.mesh, subdomain_data=tags, subdomain_id=GAMMA_C)))
            vec = f.vector if hasattr(f, "vector") else f.x.petsc_vec
            vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
            vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
            normal.append(f.x.array[self.nodes])
        normal = np.array(normal).T
        self.node_normals = normal / np.linalg.norm(normal, axis=1)[:, None]

    def separation(self, u):
        """R(u_nu) = min((-u_nu)_+, L) (UFL)."""
        s = -ufl.dot(u, self.nu)
        L = self.params.extra["L_adh"]
        return ufl.conditional(ufl.gt(s, 0.0), ufl.conditional(ufl.lt(s, L), s, L), 0.0)

    def traction(self, u):
        """-sigma_nu = p_nu(u_nu) - gamma_nu beta^2 R(u_nu) of (A1) (UFL)."""
        x = self.params.extra
        r = ufl.dot(u, self.nu)
        p_nu = x["c_nu"] * ufl.conditional(ufl.ge(r, 0.0), r, 0.0)
        return p_nu - x["gamma_nu"] * self.beta ** 2 * self.separation(u)

    def nodal_separation(self, u):
        """R(u(x_i) . nu_i) at the local nodes of Gamma_C (NumPy)."""
        d = self.mesh.geometry.dim
        u_nu = (u.x.array.reshape(-1, d)[self.nodes] * self.node_normals).sum(axis=1)
        return np.clip(-u_nu, 0.0, self.params.extra["L_adh"])

    def start(self):
        self.beta.x.array[:] = 0.0                      # off Gamma_C: not an unknown
        self.beta.x.array[self.nodes] = self.params.extra["beta0"]
        return {}

    def adhesion_step(self):
        """(A2) at the nodes of Gamma_C; u_old holds u_{n-1}."""
        x = self.params.extra
        a = x["gamma_nu"] * self.nodal_separation(self.u_old) ** 2
        old = self.beta.x.array[self.nodes]
        active = a * old > x["eps_a"]
        self.beta.x.array[self.nodes] = np.where(
            active, (old + self.k * x["eps_a"]) / (1.0 + self.k * a), old)
        return None

    def scheme(self):
        return (dd.SubStep("damage", "snes-vi", "damage_", self.damage.solve, ("damage_its",)),
                dd.SubStep("adhesion", "update", "", self.adhesion_step),
                dd.SubStep("mech", "semismooth", "mech_", self.mech.solve, ("snes_its",)))

    def contact_pressure(self):
        return self.traction(self.u)

    def scalars(self):
        n_owned = self.beta.function_space.dofmap.index_map.size_local
        mine = self.beta.x.array[self.nodes[self.nodes < n_owned]]
        lo = self.comm.allreduce(mine.min() if mine.size else np.inf, op=MPI.MIN)
        hi = self.comm.allreduce(mine.max() if mine.size else -np.inf, op=MPI.MAX)
        bonded = self.comm.allreduce(fem.assemble_scalar(self._bonded), op=MPI.SUM)
        return {**super().scalars(), "adhesive_force": float(self.contact_resultant()[1]),
                "bonded": bonded / self._length, "beta_min": lo, "beta_max": hi}

    def update_output(self):
        b.interpolate(self.von_mises, self._vm)


# %%
# The problem
# -----------

def block(comm, n):
    return rectangle(comm, (0.0, 0.0), (1.0, 0.25), 4 * n, n,
                     {4: side(0, 0.0), 2: side(1, 0.25), 3: side(1, 0.0)})


Q_LOAD = 20.0          # the total pull at t = 1


def pull(q=Q_LOAD):
    return lambda x, t: ufl.as_vector((0.0, 3.0 * q * t * x[0] ** 2))


problem = dd.Problem(model=AdhesiveKelvinVoigt, mesh=block, n=8, T=0.9, k=0.02,
                     name="bonded-block", traction=pull(),
                     boundaries={"roller": 4, "traction": 2, "adhesion": 3})


def gamma_c_history(step):
    """(x, beta, u_nu) at the nodes of Gamma_C (y = 0, sorted by x) on rank 0; None elsewhere."""
    gb, gu = dd.gather(step.model.beta), dd.gather(step.u)
    if gb is None:
        return None
    on = np.isclose(gb[0][:, 1], 0.0)
    on_u = np.isclose(gu[0][:, 1], 0.0)
    return gb[0][on, 0], gb[1][on, 0], -gu[1][on_u, 1]          # nu = (0, -1)


#: the round-off of the two computations of beta (values of order 1)
ROUND_OFF = 1e-13


def closed_form_check(t, beta, u_nu, x):
    """At every node: the exact solution of (A1) with R constant on each step (the separation
    of the step's start) against the computed beta, and the bound of backward Euler's error."""
    k = np.diff(t)
    exact, bound = beta[0].copy(), np.zeros_like(beta[0])
    for n in range(1, len(t)):
        a = x["gamma_nu"] * np.clip(-u_nu[n - 1], 0.0, x["L_adh"]) ** 2
        eq = x["eps_a"] / np.where(a > 0, a, 1.0)            # where a > 0
        above = (a > 0) & (exact > eq)
        exact = np.where(above, eq + (exact - eq) * np.exp(-a * k[n - 1]), exact)
        bound += np.where(a > 0, 0.5 * (a * k[n - 1]) ** 2
                          * np.clip(beta[n - 1] - eq, 0.0, None), 0.0)
    error = beta[-1] - exact                 # backward Euler lags: 0 <= error <= bound
    ratio = error / (bound + ROUND_OFF)
    return error, bound, ratio, exact


# %%
# The run, with the history on Gamma_C
# ------------------------------------

comm = MPI.COMM_WORLD
out = Path(os.environ.get("DAMAGE_DOLFINX_DEMO_OUT", "results")) / "adhesion"

if __name__ == "__main__" or "DAMAGE_DOLFINX_DEMO_OUT" in os.environ:
    times, betas, separations = [], [], []
    with dd.steps(problem, out / "run", overwrite=True, progress=False, figures=False) as run:
        for step in run:
            record = gamma_c_history(step)
            if record is not None:
                times.append(step.t)
                x_c, beta_c, u_nu_c = record
                betas.append(beta_c)
                separations.append(u_nu_c)
            force = step.contact_resultant()[1]
    data = AdhesiveKelvinVoigt.defaults().extra
    load = Q_LOAD * problem.T
    imbalance = abs(force - load) / load
    if comm.rank == 0:
        t, beta, u_nu = np.array(times), np.array(betas), np.array(separations)
        error, bound, ratio, exact = closed_form_check(t, beta, u_nu, data)
        bonded = x_c[beta[-1] > 0.5]
        front = bonded.max() if bonded.size else 0.0
        print(f"t = {t[-1]:.3g}: adhesive force {force:.8g}, pull {load:.8g}; "
              f"beta in [{beta[-1].min():.4g}, {beta[-1].max():.4g}], "
              f"debonding front (beta = 1/2) at x = {front:.3g}")
        worst = int(np.argmax(ratio))
        below = max(0.0, -ratio.min())       # beta below the closed form (never, for (A2))
        print(f"beta - closed form of (A1) in [{error.min():.3e}, {error.max():.3e}]; the "
              f"largest against its bound at x = {x_c[worst]:.3g}: {error[worst]:.3e} <= "
              f"{bound[worst]:.3e}")
        print(f"PHYSICS_CHECK adhesive_balance {imbalance:.3e} 1e-8 "
              f"{'PASS' if imbalance <= 1e-8 else 'FAIL'}")
        print(f"PHYSICS_CHECK beta_error_over_bound {ratio.max():.4f} 1 "
              f"{'PASS' if ratio.max() <= 1.0 else 'FAIL'}")
        print(f"PHYSICS_CHECK beta_below_closed_form {below:.3e} 1e-6 "
              f"{'PASS' if below <= 1e-6 else 'FAIL'}")
        assert imbalance <= 1e-8 and ratio.max() <= 1.0 and below <= 1e-6

        # %%
        # The bonding field along Gamma_C
        # -------------------------------
        # beta(x, t) at a few times: the bonds break first at the pulled end; the closed form
        # of (A1) (dots) at the last time.
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6.6, 3.6))
        cmap = plt.get_cmap("viridis")
        picks = [int(np.argmin(abs(t - s))) for s in (0.0, 0.4, 0.6, 0.7, 0.8, 0.85, 0.9)]
        for j, n in enumerate(picks):
            ax.plot(x_c, beta[n], "-", color=cmap(j / (len(picks) - 1)), label=f"t = {t[n]:.2f}")
        ax.plot(x_c, exact, "o", ms=3.5, mfc="none", color="C3",
                label=f"closed form of (A1)\nt = {t[-1]:.2f}")
        ax.set_xlabel(r"$x$ along $\Gamma_C$")
        ax.set_ylabel(r"bonding field $\beta$")
        ax.set_ylim(-0.03, 1.05)
        ax.set_title(r"debonding of a block pulled by $(0, 3qt x^2)$, $k$ = " + f"{problem.k:g}")
        ax.legend(fontsize=8, loc="center left", bbox_to_anchor=(1.01, 0.5))
        fig.tight_layout()
        fig.savefig(out / "beta_along_gamma_c.png", dpi=120)
    else:
        assert imbalance <= 1e-8
