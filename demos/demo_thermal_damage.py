r"""
Temperature and damage: a field of its own with its own solve
=============================================================

A model of your own with a third field: the temperature rise :math:`\theta` above the ambient
(initial and ambient value 0) of a quasistatic Kelvin-Voigt body with damage (the body of
Section 2.2, clamped, pulled by a traction). The temperature has its own heat equation, solved
at every step, heated by the mechanical dissipation, cooled through the boundary; it acts back
on the body twice, by thermal expansion and by thermal softening of the damage source.

The model (:math:`\mathcal{A} = \mathcal{B}/m_{visc}`, :math:`\mathcal{B}` plane stress,
:math:`\alpha` the expansion coefficient, :math:`I` the identity):

.. math::

   \varepsilon_e = \varepsilon(u) - \alpha\theta I, \qquad
   \sigma = \mathcal{A}\varepsilon(\dot u) + \zeta\,\Phi_L(\mathcal{B}\varepsilon_e),
   \qquad -\operatorname{div}\sigma = 0                                             \tag{T1}

.. math::

   \dot\zeta - \kappa\Delta\zeta \in \phi_\theta(\varepsilon_e, \zeta, \theta) - \partial I_{[\zeta_*, 1]}(\zeta),
   \qquad \phi_\theta = \phi(\varepsilon_e, \zeta) - \tfrac12 s_\theta \lambda_u\, \theta_+\, \Psi_q(\varepsilon_e)   \tag{T2}

.. math::

   c\,\dot\theta - \operatorname{div}(K\nabla\theta) = r, \qquad
   r = \beta\bigl(\mathcal{A}\varepsilon(\dot u):\varepsilon(\dot u)
       + \psi(\varepsilon_e)\,(-\dot\zeta)_+\bigr), \qquad
   -K\nabla\theta\cdot\nu = h\,\theta \ \text{on}\ \partial\Omega                     \tag{T3}

with :math:`\phi` the package's damage law (variant A (1.3) by default),
:math:`\psi(\varepsilon_e) = \tfrac12\Phi_L(\mathcal{B}\varepsilon_e):\varepsilon_e` the elastic
energy density of the undamaged material and :math:`\beta` the fraction of the dissipation that
becomes heat (Taylor-Quinney). The scheme, at each step :math:`t_{n-1} \to t_n`:

1. (T2) the damage step of 2.2 (obstacle inclusion in :math:`[\zeta_*, 1]`) with the explicit
   source :math:`\phi_\theta(\varepsilon_{e,n-1}, \zeta_{n-1}, \theta_{n-1})`,
   :math:`\varepsilon_{e,n-1} = \varepsilon(u_{n-1}) - \alpha\theta_{n-1} I`;
2. (T1) the velocity, linear with a matrix assembled once:

   .. math::

      (\mathcal{A}\varepsilon(v_n), \varepsilon(w)) = L_n(w)
      - (\zeta_{n-1}\Phi_L(\mathcal{B}\varepsilon_{e,n-1}), \varepsilon(w));          \tag{T4}

3. (T3) the temperature by backward Euler, linear, symmetric positive definite, its matrix
   assembled once:

   .. math::

      \Bigl(c\,\frac{\theta_n - \theta_{n-1}}{k}, \eta\Bigr) + (K\nabla\theta_n, \nabla\eta)
      + \int_{\partial\Omega} h\,\theta_n\,\eta = (r_n, \eta), \qquad
      r_n = \beta\Bigl(\mathcal{A}\varepsilon(v_n):\varepsilon(v_n)
      + \psi(\varepsilon_{e,n-1})\,\frac{(\zeta_{n-1} - \zeta_n)_+}{k}\Bigr);          \tag{T5}

4. :math:`u_n = u_{n-1} + k v_n`.

The decisions. *Weak coupling*: the heat equation carries the dissipation and not the
thermoelastic term :math:`-\alpha\theta\,\zeta\,\mathrm{tr}\,\mathcal{B}\varepsilon(\dot u)`
(small against the dissipation at the strain rates of damage). *Staggered*: each field is
solved once per step from the newest values of the others, the elastic and damage coupling
terms explicit as in 2.2 (so its limit :math:`k \le 2/m_{visc}` is unchanged); the heat step is
implicit and unconditionally stable. *The source*: the viscous dissipation at
:math:`v_n` and the elastic energy released by the damage of the step, positive parts only
(healing releases no heat). *Back coupling*: the elastic strain :math:`\varepsilon_e`, not the
total strain, drives both the stress and the damage (a freely expanding body is not damaged by
heating), and the damage source grows with :math:`\theta_+` (thermal softening, factor
:math:`1 + s_\theta\theta_+`). :math:`\theta` is state: ``old_state`` copies it, so it is
checkpointed and checked after every step, and the damage step declares that it reads
:math:`\theta_{n-1}` (the contracts then refuse an ``old_state`` without it).

Two physics checks. The discrete heat balance: (T5) with :math:`\eta = 1` (a P1 function) gives

.. math::

   \int_\Omega c\,\theta_n - \int_\Omega c\,\theta_{n-1}
   = k\Bigl(\int_\Omega r_n - \int_{\partial\Omega} h\,\theta_n\Bigr),                \tag{T6}

evaluated here at every step from the live fields with forms of the script's own, summed over
the run, and compared relative to the heat produced: it holds to the heat solver's tolerance
and fails when the temperature step does not solve (T5) with the source of this step. And a
uniform case (an insulated square on rollers in uniaxial tension), where the scheme is a
recursion of a few numbers, written in NumPy independently of the finite elements: the strain,
damage and temperature of the run must follow it to round-off.
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

import damage_dolfinx as dd
from damage_dolfinx import blocks as b
from damage_dolfinx.geometries.rectangle import rectangle, side


class ThermalKelvinVoigt(dd.Model):
    """Quasistatic Kelvin-Voigt body with damage and temperature: (T4), (T2), (T5)."""

    id = "kv-thermal"
    title = "quasistatic Kelvin-Voigt body with damage and temperature"
    extra_roles = {"roller": 4}                        # u.nu = 0 on a face (a coordinate plane)
    stability_limit = "explicit elastic term: k <= 2/m_visc"
    checkpoint_fields = ("u", "zeta", "v", "theta")
    history_columns = ("theta_max", "thermal_energy", "heat_source", "heat_outflow", "heat_its")
    old_state = (("u", "u_old"), ("zeta", "zeta_old"), ("theta", "theta_old"))
    update = ("u", "u_old", "v")                       # step 4: u_n = u_{n-1} + k v_n

    @classmethod
    def defaults(cls):
        p = dd.model_defaults("2.2")
        return dataclasses.replace(p, extra={
            "m_visc": 10.0,       # A = B / m_visc
            "alpha": 2e-3,        # thermal expansion
            "s_theta": 0.5,       # thermal softening of the damage source
            "c_heat": 1.0,        # heat capacity per volume
            "K_heat": 0.01,       # conductivity
            "h_heat": 1.0,        # boundary heat transfer coefficient
            "beta": 0.9})         # fraction of the dissipation turned into heat

    @classmethod
    def k_max(cls, params):
        return dd.model_class("2.2").k_max(params)  # the same explicit elastic term

    def __init__(self, data):
        super().__init__(data)
        p, x, msh = self.params, self.params.extra, self.mesh
        V, Z = b.vector_p1(msh), b.scalar_p1(msh)
        self.u, self.u_old, self.v = (fem.Function(V, name=s) for s in ("u", "u_old", "v"))
        self.zeta, self.zeta_old = fem.Function(Z, name="zeta"), fem.Function(Z, name="zeta_old")
        self.theta = fem.Function(Z, name="theta")
        self.theta_old = fem.Function(Z, name="theta_old")
        k = data.time.k
        tags = data.geometry.facet_tags
        ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
        I = ufl.Identity(msh.geometry.dim)
        self.eps_e_old = b.eps(self.u_old) - x["alpha"] * self.theta_old * I   # eps_e,n-1

        # (T2) the damage step; it reads theta_{n-1}: declared, so old_state must copy it
        self.damage = self.obstacle_damage_step()
        self.damage.previous_state += ((self.theta, self.theta_old),)

        # (T4) the velocity, matrix assembled once
        w = ufl.TestFunction(V)
        a = ufl.inner(b.viscous_stress(ufl.TrialFunction(V), p.E, p.nu, x["m_visc"]),
                      b.eps(w)) * ufl.dx
        elastic = self.zeta_old * b.Phi_L(b.B(self.eps_e_old, p.E, p.nu), p.L_trunc)
        f_B, f_N = self.loads()
        l = b.load(w, f_B, f_N, ds(2)) - ufl.inner(elastic, b.eps(w)) * ufl.dx
        bcs = [b.clamped(V, tags, 1)] + b.bilateral(V, tags, 4)
        self.mech = b.LinearSolver(a, l, bcs, "mech_", self.context, constant_matrix=True)

        # (T5) the temperature, backward Euler, matrix assembled once
        self.source = self.heat_source(self.v, self.zeta, self.zeta_old, self.eps_e_old)
        th, eta = ufl.TrialFunction(Z), ufl.TestFunction(Z)
        c, K, h = x["c_heat"], x["K_heat"], x["h_heat"]
        dA = ufl.Measure("ds", domain=msh)                  # the whole boundary
        a_th = (c / k * th * eta + K * ufl.inner(ufl.grad(th), ufl.grad(eta))) * ufl.dx \
            + h * th * eta * dA
        l_th = (c / k * self.theta_old + self.source) * eta * ufl.dx
        self.heat = b.LinearSolver(a_th, l_th, [], "heat_", self.context, constant_matrix=True)

        # the heat balance's terms (T6), and the outputs
        self._energy = fem.form(c * self.theta * ufl.dx)
        self._source = fem.form(self.source * ufl.dx)
        self._outflow = fem.form(h * self.theta * dA)
        Q = b.scalar_dg0(msh)
        self.von_mises = fem.Function(Q, name="von_mises")
        sigma = b.viscous_stress(self.v, p.E, p.nu, x["m_visc"]) + self.zeta * b.Phi_L(
            b.B(b.eps(self.u) - x["alpha"] * self.theta * I, p.E, p.nu), p.L_trunc)
        self._vm = b.expression(b.von_mises(sigma), Q)
        self.output_fields = [self.u, self.v, self.zeta, self.theta, self.von_mises]
        self.error_components = [("u", self.u, "V"), ("zeta", self.zeta, "L2"),
                                 ("theta", self.theta, "L2")]

    def damage_source(self, e, z):
        """(T2): the run's law of the elastic strain, softened by theta_{n-1} (e is
        eps(u_{n-1}), z is zeta_{n-1}: obstacle_damage_step's explicit source)."""
        p, x = self.params, self.params.extra
        e_el = e - x["alpha"] * self.theta_old * ufl.Identity(e.ufl_shape[0])
        psi_q = ufl.min_value(ufl.inner(e_el, e_el), p.q_star)
        return (super().damage_source(e_el, z)
                - 0.5 * x["s_theta"] * p.lam_u * ufl.max_value(self.theta_old, 0.0) * psi_q)

    def heat_source(self, v, zeta, zeta_old, eps_e_old):
        """r_n of (T5): beta (viscous dissipation + elastic energy released by damage)."""
        p, x = self.params, self.params.extra
        k = self.data.time.k
        viscous = ufl.inner(b.viscous_stress(v, p.E, p.nu, x["m_visc"]), b.eps(v))
        psi = 0.5 * ufl.inner(b.Phi_L(b.B(eps_e_old, p.E, p.nu), p.L_trunc), eps_e_old)
        return x["beta"] * (viscous + psi * ufl.max_value(zeta_old - zeta, 0.0) / k)

    def scheme(self):
        return (dd.SubStep("damage", "snes-vi", "damage_", self.damage.solve, ("damage_its",)),
                dd.SubStep("mech", "linear", "mech_", self._velocity, ("mech_its",)),
                dd.SubStep("heat", "linear", "heat_", self._temperature, ("heat_its",)))

    def _velocity(self):
        return self.mech.solve(self.v)

    def _temperature(self):
        return self.heat.solve(self.theta)

    def scalars(self):
        total = lambda f: self.comm.allreduce(fem.assemble_scalar(f), op=MPI.SUM)  # noqa: E731
        owned = self.theta.x.array[:self.theta.function_space.dofmap.index_map.size_local]
        top = self.comm.allreduce(float(owned.max()) if owned.size else -np.inf, op=MPI.MAX)
        return {**super().scalars(), "theta_max": top, "thermal_energy": total(self._energy),
                "heat_source": total(self._source), "heat_outflow": total(self._outflow)}

    def update_output(self):
        b.interpolate(self.von_mises, self._vm)


# %%
# The problem
# -----------
# A bar :math:`(0, 1) \times (0, 0.25)` clamped on its left side (tag 1), pulled on its right
# side (tag 2) by a traction :math:`(q t, 0)`; the whole boundary exchanges heat with the
# ambient (coefficient :math:`h`).

comm = MPI.COMM_WORLD
out = Path(os.environ.get("DAMAGE_DOLFINX_DEMO_OUT", "results")) / "thermal_damage"
Q_LOAD = 200.0


def bar(comm, n):
    return rectangle(comm, (0.0, 0.0), (1.0, 0.25), 4 * n, n,
                     {1: side(0, 0.0), 2: side(0, 1.0)})


problem = dd.Problem(model=ThermalKelvinVoigt, mesh=bar, n=4, T=1.0, k=0.05,
                     name="thermal-bar", boundaries={"clamped": 1, "traction": 2},
                     traction=lambda x, t: ufl.as_vector((Q_LOAD * t, 0.0)))


# %%
# The heat balance, step by step
# ------------------------------
# After each step the script evaluates (T6) from the live fields: the thermal energy
# :math:`\int c\theta`, the source :math:`r_n` (from :math:`v_n`, :math:`\zeta_n`,
# :math:`\zeta_{n-1}`, :math:`u_{n-1}`, :math:`\theta_{n-1}` as the model holds them at the end of
# the step) and the outflow :math:`\int h\theta_n`, with forms of its own.

def heat_balance(steps, k):
    """The defect of (T6) summed over the steps of the iterator ``steps`` (time step ``k``),
    relative to the heat produced, and the rows (t, thermal energy, heat produced, min zeta)."""
    total = lambda f: comm.allreduce(fem.assemble_scalar(f), op=MPI.SUM)  # noqa: E731
    forms, rows, defect, produced = None, [], 0.0, 0.0
    for step in steps:
        m = step.model
        if forms is None:
            p, x = m.params, m.params.extra
            I = ufl.Identity(m.mesh.geometry.dim)
            eps_e = b.eps(m.u_old) - x["alpha"] * m.theta_old * I
            psi = 0.5 * ufl.inner(b.Phi_L(b.B(eps_e, p.E, p.nu), p.L_trunc), eps_e)
            visc = ufl.inner(b.B(b.eps(m.v), p.E, p.nu), b.eps(m.v)) / x["m_visc"]
            r = x["beta"] * (visc + psi * ufl.max_value(m.zeta_old - m.zeta, 0.0) / k)
            forms = [fem.form(f) for f in (x["c_heat"] * m.theta * ufl.dx, r * ufl.dx,
                                           x["h_heat"] * m.theta * ufl.ds(m.mesh))]
            energy_before = total(forms[0])
        energy, source, outflow = (total(f) for f in forms)
        if step.n > 0:
            defect += energy - energy_before - k * (source - outflow)
            produced += k * source
        energy_before = energy
        rows.append((step.t, energy, produced, m.zeta_min()))
    return abs(defect) / max(produced, 1e-300), rows


#: the demo runs as a script and in the site; imported (by a test), it defines the model only
RUN = __name__ == "__main__" or "DAMAGE_DOLFINX_DEMO_OUT" in os.environ

if RUN:
    with dd.steps(problem, out / "run", overwrite=True, progress=False, figures=False) as run:
        balance, rows = heat_balance(run, problem.k)
    summary = run.summary
    if comm.rank == 0:
        t, energy, produced, zmin = np.array(rows).T
        print(f"{summary['status']} at t = {summary['t_final']:.3g}: heat produced "
              f"{produced[-1]:.6g}, thermal energy {energy[-1]:.6g}, min zeta {zmin[-1]:.4g}, "
              f"max theta {summary['final']['theta_max']:.4g}")
        print(f"PHYSICS_CHECK heat_balance {balance:.3e} 1e-9 "
              f"{'PASS' if balance <= 1e-9 else 'FAIL'}")
    assert balance <= 1e-9

# %%
# A uniform case: the scheme in closed form
# -----------------------------------------
# The unit square on rollers (:math:`u_1 = 0` at :math:`x_1 = 0`, :math:`u_2 = 0` at
# :math:`x_2 = 0`, tag 4), pulled by :math:`(q t, 0)` on :math:`x_1 = 1`, insulated
# (:math:`h = 0`), undamaged at :math:`t = 0`: the stress is uniaxial and every field uniform,
# which P1 elements hold exactly. The scheme is then a recursion for the strain
# :math:`\varepsilon_n`, :math:`\zeta_n` and :math:`\theta_n` (the damage step without the gradient,
# clipped to :math:`[\zeta_*, 1]`; (T4) with :math:`\varepsilon(v_n) = m_{visc}\mathcal{B}^{-1}
# \bigl(\mathrm{diag}(q t_n, 0) - \zeta_{n-1}\Phi_L(\mathcal{B}\varepsilon_{e,n-1})\bigr)`; (T5)
# with :math:`\theta_n = \theta_{n-1} + k r_n / c`), written here in NumPy, independently of the
# finite elements; the run must reproduce it.

def square(comm, n):
    def rollers(x):
        return side(0, 0.0)(x) | side(1, 0.0)(x)
    return rectangle(comm, (0.0, 0.0), (1.0, 1.0), n, n, {4: rollers, 2: side(0, 1.0)})


def uniform_recursion(p, x, q, k, steps):
    """(strain, zeta, theta) after ``steps`` steps of the scheme for the uniform state."""
    E, nu, m = p.E, p.nu, x["m_visc"]

    def B(e):  # plane stress
        return E * nu / (1 - nu ** 2) * np.trace(e) * np.eye(2) + E / (1 + nu) * e

    def B_inv(s):
        return ((1 + nu) * s - nu * np.trace(s) * np.eye(2)) / E

    def phi(e, z):  # the thesis law of variant A, (1.3)
        ez = min(max(z, p.zeta_star), 1.0)
        return (p.lam_D * (1 - ez) / ez - 0.5 * p.lam_u * min(np.sum(e * e), p.q_star)
                - p.lam_w)

    e, z, th = np.zeros((2, 2)), 1.0, 0.0
    for n in range(1, steps + 1):
        e_el = e - x["alpha"] * th * np.eye(2)
        soft = 0.5 * x["s_theta"] * p.lam_u * max(th, 0.0) * min(np.sum(e_el * e_el), p.q_star)
        z_new = min(max(z + k * (phi(e_el, z) - soft), p.zeta_star), 1.0)
        stress = np.clip(B(e_el), -p.L_trunc, p.L_trunc)
        ev = m * B_inv(np.diag([q * n * k, 0.0]) - z * stress)
        psi = 0.5 * np.sum(stress * e_el)
        r = x["beta"] * (np.sum(B(ev) * ev) / m + psi * max(z - z_new, 0.0) / k)
        th += k * r / x["c_heat"]
        e, z = e + k * ev, z_new
    return e, z, th


def uniform_defect(uniform, out):
    """Run ``uniform`` (the square on rollers) to its T; the largest relative difference of
    its strain, damage and temperature from the recursion, and the recursion's values."""
    with dd.steps(uniform, out, overwrite=True, progress=False, figures=False) as run:
        for step in run:
            m = step.model
    eps_h = fem.Function(b.tensor_dg0(m.mesh))
    b.interpolate(eps_h, b.expression(b.eps(m.u), b.tensor_dg0(m.mesh)))
    local = lambda f: f.x.array[:f.function_space.dofmap.index_map.size_local]  # noqa: E731
    e, z, th = uniform_recursion(m.params, m.params.extra, Q_LOAD, uniform.k,
                                 m.data.time.num_steps)
    worst = 0.0
    for values, exact in ((local(eps_h).reshape(-1, 2, 2), e), (local(m.zeta), z),
                          (local(m.theta), th)):
        if values.size:
            worst = max(worst, float(np.abs(values - exact).max() / np.abs(exact).max()))
    return comm.allreduce(worst, op=MPI.MAX), (e, z, th)


uniform = dd.Problem(model=ThermalKelvinVoigt, mesh=square, n=2, T=1.0, k=0.05,
                     name="thermal-uniform", params={"h_heat": 0.0},
                     boundaries={"roller": 4, "traction": 2},
                     traction=lambda x, t: ufl.as_vector((Q_LOAD * t, 0.0)))
if RUN:
    worst, (e, z, th) = uniform_defect(uniform, out / "uniform")
    if comm.rank == 0:
        print(f"uniform case at t = {uniform.T:g}: eps_11 = {e[0, 0]:.6g}, zeta = {z:.6g}, "
              f"theta = {th:.6g} (closed form)")
        print(f"PHYSICS_CHECK uniform_closed_form {worst:.3e} 1e-9 "
              f"{'PASS' if worst <= 1e-9 else 'FAIL'}")
    assert worst <= 1e-9

# %%
# What the temperature does to the damage
# ---------------------------------------
# The same run without thermal softening (:math:`s_\theta = 0`): the bar is hottest at its
# centre, farthest from the cooled boundary, and with softening it damages most there.

if RUN:
    cold = dd.run(problem, out / "no_softening", overrides={"s_theta": 0.0}, overwrite=True,
                  progress=False, figures=False)
    if comm.rank == 0:
        print(f"min zeta at t = {problem.T:g}: {summary['final']['zeta_min']:.4g} with thermal "
              f"softening, {cold['final']['zeta_min']:.4g} without")

# %%
# Temperature and damage at the end
# ---------------------------------
# The fields at T, and the heat produced, what the body holds and the difference: what left
# through the boundary.

if RUN and comm.rank == 0:
    import matplotlib.pyplot as plt
    import matplotlib.tri as mtri
    with np.load(out / "run" / "fields_final.npz") as f:
        fields = {key: f[key] for key in f.files}
    fig, axes = plt.subplots(3, 1, figsize=(6.0, 6.4),
                             gridspec_kw={"height_ratios": [1, 1, 1.6]})
    for ax, key, label, cmap in ((axes[0], "theta", r"temperature rise $\theta$", "inferno"),
                                 (axes[1], "zeta", r"damage $\zeta$", "viridis")):
        xy = fields[f"{key}_coords"]
        tri = mtri.Triangulation(xy[:, 0], xy[:, 1])
        art = ax.tricontourf(tri, fields[key].ravel(), levels=20, cmap=cmap)
        ax.set_aspect("equal")
        ax.set_title(f"{label} at t = {summary['t_final']:g}", fontsize=10)
        fig.colorbar(art, ax=ax, shrink=0.9)
    axes[2].plot(t, produced, "-", label=r"heat produced $\sum k \int r_n$")
    axes[2].plot(t, energy, "o", ms=3, label=r"thermal energy $\int c\,\theta$")
    axes[2].plot(t, produced - energy, "--", label="left through the boundary")
    axes[2].set_xlabel("time $t$")
    axes[2].set_ylabel("heat")
    axes[2].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "thermal_damage.png", dpi=120)
