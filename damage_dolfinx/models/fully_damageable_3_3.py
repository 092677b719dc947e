"""Section 3.3: dynamic, fully damageable frictionless contact (damage scales the viscosity, the
elasticity and the contact pressure), damage by the obstacle inclusion (variant A), scheme
(3.158)-(3.160):

    (1) zeta_n in K^h:  (zeta_n - zeta_{n-1}, xi - zeta_n) + k kappa (grad zeta_n, grad(xi - zeta_n))
                        >= k (phi_A(eps(u_{n-1}), eta_*(zeta_{n-1})), xi - zeta_n)
                                                               (3.158), SNES vinewtonrsls
    (2) v_n in V^h:     (rho (v_n - v_{n-1})/k, w) + (zeta_n A eps(v_n), eps(w))
                        = L_n(w) - (zeta_{n-1} Phi_L(B eps(u_{n-1})), eps(w))
                          - int_{Gamma_C} zeta_{n-1} c_nu (u_{n-1}.nu - gap)_+ w.nu ds
                                                               (3.159), linear
    (3) u_n = u_{n-1} + k v_n                                  (3.160)

Order matters: the viscosity of (2) uses the NEW damage zeta_n of (1), so the matrix of (2)
changes every step; it is re-assembled into the same PETSc Mat and solved by CG + Jacobi (prefix
``mech_``; the mass rho/k M dominates when m_visc is large, Examples 2-3). V = {v = 0 on
Gamma_D} (Gamma_D may be empty: the mass keeps (2) definite). u_0 = v_0 = 0.

Parameters in ``extra``: rho, m_visc, c_nu, gap, ``damage_active`` (False: zeta frozen at zeta_0),
``stability_check`` (warn | error | off; k against the limit of the explicit elastic and contact
forces, stability.py; docs/models.md, "Stability of the explicit terms"), ``elastic_term`` =
``explicit`` (the thesis) or ``implicit`` (a deviation, NOT the thesis scheme: elastic and contact
forces at u_{n-1} + k v_n, a semismooth Newton solve per step, prefix ``mech_``),
``initial_damage`` (a key of ``builders["zeta0"]``, Example 2's cases a/b).

The step is the generic one (models/base.py) with two hooks, where this scheme is special:
``begin_step`` starts the CG of (2) from the cubic extrapolation of v_{n-1}, ..., v_{n-4}
(taken before the old state is copied, and shifted), and ``end_step`` samples the damage
profiles of Example 2.

Output: von Mises of the total stress zeta_n A eps(v_n) + zeta_n Phi_L(B eps(u_n)) (DG0);
history columns v_L2, the maximal interpenetration (u.nu - gap)_+ over the Gamma_C vertices and
its location, and zeta at ``builders["probe"]``; damage profiles along x_2 =
``builders["profile_x2"]`` every ``builders["profile_every"]`` s (plus the latest state) in
summary.json. Convergence errors in the norm of Cor. 3.3: ||u||_L2 + ||zeta||_L2.
"""
from __future__ import annotations

import math
import time

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from damage_dolfinx.core.tags import GAMMA_C, GAMMA_D, GAMMA_N

from damage_dolfinx import compat
from damage_dolfinx.numerics import bookkeeping
from damage_dolfinx.numerics.boundary import clamped
from damage_dolfinx.forms.constitutive import eps, von_mises
from damage_dolfinx.forms.fully_damageable import (implicit_velocity_residual, total_stress,
                                      velocity_matrix_parts, velocity_rhs_boundary,
                                      velocity_step_forms)
from damage_dolfinx.core.parameters import InputError, ModelParameters
from damage_dolfinx.numerics.solvers import LinearSolver, NonlinearSolver
from damage_dolfinx.models.monitors import ContactMonitor, DamageProfiles, ZetaProbe  # noqa: F401 (also imported from here)
from damage_dolfinx.numerics.zeta_linear import VelocitySolver
from damage_dolfinx.models.base import DAMAGE_A, Model, SubStep

#: velocity system (3.159): SPD, mass-dominated for small k -> CG + Jacobi, nonzero start (see
#: VELOCITY_EXTRAPOLATION);
#: override with -mech_ksp_type / -mech_pc_type (e.g. hypre)
MECH_DEFAULTS = {"ksp_type": "cg", "pc_type": "jacobi", "ksp_rtol": 1e-12, "ksp_atol": 1e-50,
                 "ksp_max_it": 5000, "ksp_initial_guess_nonzero": True}

#: per-step cost: the matrix of (3.159) from the nodal zeta_n by a precomputed sparse
#: map instead of a re-assembly (serial; equal to round-off); with Phi_L = identity the
#: right-hand side too (FAST_RHS); CG started from the cubic extrapolation
#: 4 v_{n-1} - 6 v_{n-2} + 4 v_{n-3} - v_{n-4} instead of v_{n-1} (same solution to rtol 1e-12;
#: fewer CG iterations per step than a linear or quadratic extrapolation, benchmarks/README.md,
#: "Why the defaults"). Switches to time
#: or check the step both ways.
FAST_MATRIX = True
FAST_RHS = True
VELOCITY_EXTRAPOLATION = True


class FullyDamageableContact(Model):
    """Problem VP^{hk} of Section 3.3."""

    id = "3.3"
    title = "dynamic fully damageable body, normal compliance"
    contact_roles = ("normal_compliance",)
    dynamic = True
    checks_time_step = True  # k against its eigenvalue estimate (stability_check)
    stability_limit = "explicit elastic and contact forces (eigenvalue estimate)"
    checkpoint_fields = ("u", "zeta", "v")
    history_columns = ("v_L2",)  # + the contact monitor's and the probe's columns
    old_state = (("u", "u_old"), ("v", "v_old"), ("zeta", "zeta_old"))
    update = ("u", "u_old", "v")  # (3.160) u_n = u_{n-1} + k v_n

    #: the rules of the model's own data (name -> (test, what it must be))
    rules = {
        "damage_atol_rel": (lambda v: v >= 0, "(the obstacle step's absolute tolerance relative to "
                            "||l||) must be >= 0"),
        "elastic_term": (lambda v: v in ("explicit", "implicit"),
                         "(Section 3.3: explicit = thesis scheme, implicit = a deviation) must be "
                         "'explicit' or 'implicit'"),
        "initial_damage": (lambda v: v in ("a", "b"),
                           "(Section 3.3 Ex. 2: a = centre [2.5,3.5]^2, b = bottom [2.5,3.5]x[0,1]) "
                           "must be 'a' or 'b'"),
    }

    @classmethod
    def defaults(cls) -> ModelParameters:
        return ModelParameters(E=1e4, nu=0.3, **dict(DAMAGE_A, kappa=1.0, lam_D=0.0),
                               extra={"rho": 1.0, "m_visc": 100.0, "c_nu": 1e4, "gap": 0.0,
                                      "damage_active": True, "stability_check": "error",
                                      "elastic_term": "explicit"})

    @classmethod
    def declared_columns(cls, problem, dim: int) -> list:
        """v_L2, the contact monitor's (penetration_max, penetration_x1..x<dim>) and the
        probe's (zeta_probe, when ``builders["probe"]`` names a point)."""
        return (["v_L2", "penetration_max"] + [f"penetration_x{i + 1}" for i in range(dim)]
                + ([] if problem.builders.get("probe") is None else ["zeta_probe"]))

    def __init__(self, data, mech_prefix="mech_", damage_prefix="damage_"):
        super().__init__(data)
        p, msh, x = self.params, self.mesh, data.params.extra
        V, Z = compat.vector_p1(msh), compat.scalar_p1(msh)
        self.u, self.u_old = fem.Function(V, name="u"), fem.Function(V, name="u_old")
        self.v, self.v_old = fem.Function(V, name="v"), fem.Function(V, name="v_old")
        # v_{n-3}, v_{n-4} of the CG start's extrapolation (checkpointed: a resume is exact)
        self._v_older = [fem.Function(V, name=f"v_older{i}") for i in (3, 4)]
        self.zeta, self.zeta_old = fem.Function(Z, name="zeta"), fem.Function(Z, name="zeta_old")
        self.k = data.time.k
        self.rho, self.m_visc = float(x["rho"]), float(x["m_visc"])
        self.c_nu, self.gap = float(x["c_nu"]), float(x.get("gap", 0.0))
        self.damage_active = bool(x.get("damage_active", True))
        self.elastic_term = x.get("elastic_term", "explicit")
        self.extrapolate = VELOCITY_EXTRAPOLATION
        self.error_components = [("u", self.u, "L2"), ("zeta", self.zeta, "L2")]  # Cor. 3.3

        # (3.158): damage obstacle step, source phi_A(eps(u_{n-1}), eta_*(zeta_{n-1}))
        self.damage = None
        if self.damage_active:
            self.damage = self.obstacle_damage_step(damage_prefix)
            # ``damage_atol_rel`` (the wrench: 0) replaces the obstacle step's absolute
            # tolerance 1e-9 ||l|| (damage.OBSTACLE_ATOL_REL) by snes_atol = 1e-12 alone; with
            # 1e-9 ||l|| a step whose increment has a smaller residual keeps zeta_{n-1}, which
            # dropped the wrench's damage up to t = 0.3 and in many steps up to t = 1.4
            rel = x.get("damage_atol_rel")
            if rel is not None:
                if not float(rel) >= 0.0:
                    raise InputError(f"damage_atol_rel must be >= 0, got {rel!r}")
                self.damage.atol_rel = float(rel)

        # (3.159): velocity with the new damage in the viscosity
        tags = data.geometry.facet_tags
        ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
        self.n_facet = ufl.FacetNormal(msh)
        f_B, f_N = self.loads()
        const = lambda value: fem.Constant(msh, float(value))  # noqa: E731
        args = (self.v_old, self.u_old, self.zeta, self.zeta_old, const(self.rho), const(self.k),
                p.E, p.nu, self.m_visc, p.L_trunc, p.zeta_star, const(self.c_nu), const(self.gap),
                self.n_facet, f_B, f_N, ds(GAMMA_N), ds(GAMMA_C))
        self.bcs = [clamped(V, tags, GAMMA_D)]
        w = ufl.TestFunction(V)
        if self.elastic_term == "explicit":
            a, l = velocity_step_forms(ufl.TrialFunction(V), w, *args)
            if self.comm.size == 1 and FAST_MATRIX:  # no re-assembly per step
                parts = velocity_matrix_parts(ufl.TrialFunction(V), w, args[4], args[5], p.E,
                                              p.nu, self.m_visc)
                rhs = None  # Phi_L = identity: l by the same sparse maps (clamped: g = 0)
                if FAST_RHS and (p.L_trunc is None or math.isinf(p.L_trunc)):
                    rhs = (velocity_rhs_boundary(w, self.u_old, self.zeta_old, p.zeta_star,
                                                 *args[11:]), self.v_old, self.u_old,
                           self.zeta_old, self.m_visc)
                self.mech = VelocitySolver(a, l, self.bcs, mech_prefix, self.context, V,
                                           *parts, self.zeta, rhs, defaults=MECH_DEFAULTS)
            else:
                self.mech = LinearSolver(a, l, self.bcs, mech_prefix, self.context,
                                         constant_matrix=False, defaults=MECH_DEFAULTS)
        elif self.elastic_term == "implicit":  # deviation from the thesis scheme
            F = implicit_velocity_residual(self.v, w, *args)
            self.mech = NonlinearSolver(F, self.v, self.bcs, mech_prefix, self.context)
        else:
            raise InputError("elastic_term must be 'explicit' or 'implicit', "
                             f"got {self.elastic_term!r}")
        self.stability = self._stability_check(V, x, ds(GAMMA_C))

        # output: von Mises of the total stress (docs/models.md, "Output conventions"), DG0
        Q = compat.scalar_dg0(msh)
        self.von_mises = fem.Function(Q, name="von_mises")
        sigma = total_stress(self.v, self.u, self.zeta, p.E, p.nu, self.m_visc, p.L_trunc,
                             p.zeta_star)
        self._vm_expr = compat.expression(von_mises(sigma), Q)
        self.output_fields = [self.u, self.v, self.zeta, self.von_mises]
        self.contact = ContactMonitor(V, tags, GAMMA_C, self.gap)
        self.probe = ZetaProbe(Z, data.builders.get("probe"))
        choice = x.get("initial_damage")
        line = data.builders.get("profile_x2")
        if isinstance(line, dict):
            line = line.get(choice)
        self.profiles = DamageProfiles(Z, line, data.builders.get("profile_every", 0.5), self.k)
        self.extra_history_columns = self.declared_columns(self.data, msh.topology.dim)
        self.timings = {"damage": 0.0, "velocity": 0.0,
                        "stability": self.stability.get("time_s", 0.0)}
        self._prefixes = damage_prefix, mech_prefix
        self._v_guess = None

    # -- the scheme
    def start(self) -> dict:
        self.profiles.sample(self.zeta, self.t)
        return {}

    def scheme(self) -> tuple:
        """(3.158) (none when ``damage_active`` is off: 0 iterations), then (3.159): by CG from
        the extrapolated start (``explicit``, the thesis), or semismooth Newton (``implicit``)."""
        damage_prefix, mech_prefix = self._prefixes
        damage = SubStep("damage", "snes-vi", damage_prefix,                       # (3.158)
                         self.damage.solve if self.damage else None, its=("damage_its",))
        if self.elastic_term == "explicit":
            return damage, SubStep("velocity", "linear", mech_prefix, self._velocity,
                                   its=("mech_its",))                                # (3.159)
        return damage, SubStep("velocity", "semismooth", mech_prefix, self.mech.solve,
                               its=("snes_its",))                                    # implicit

    def begin_step(self):
        """The CG start of (3.159): 4 v_{n-1} - 6 v_{n-2} + 4 v_{n-3} - v_{n-4}, from the
        velocities before the old state is copied; v_{n-3}, v_{n-4} move on."""
        if not (self.extrapolate and self.elastic_term == "explicit"):
            return
        if not hasattr(self, "_arrays"):  # views of the Functions' values (stable)
            self._arrays = [f.x.array for f in (self.v, self.v_old, *self._v_older)]
        v, v_old, v3, v4 = self._arrays
        self._v_guess = 4.0 * (v + v3) - 6.0 * v_old - v4
        v4[:] = v3
        v3[:] = v_old

    def _velocity(self) -> int:
        if self._v_guess is not None:
            self.v.x.array[:] = self._v_guess
        return self.mech.solve(self.v)

    def end_step(self, stats: dict):
        self.profiles.sample(self.zeta, self.t)

    def checkpoint_state(self) -> dict:
        """u, zeta, v and, for the CG start's extrapolation, v_{n-2}, v_{n-3}, v_{n-4}: without
        them a resumed run starts its CG elsewhere and differs at the solver tolerance (2e-11).
        ``monitors``: what summary.json reports over all steps (the maximal interpenetration,
        its time and place; the first time the probe reaches zeta_star, NaN: not yet), so that
        a resumed run reports the maximum over the whole run (collective)."""
        state = super().checkpoint_state()
        if self.extrapolate and self.elastic_term == "explicit":
            state.update(v_old=self.v_old, v_older3=self._v_older[0], v_older4=self._v_older[1])
        first = self.probe.first_zeta_star_time
        self._monitors = np.array(self.contact.state() + [math.nan if first is None else first])
        state["monitors"] = self._monitors
        return state

    def restore(self, n: int):
        super().restore(n)
        *contact, first = self._monitors
        self.contact.set_state(contact)
        self.probe.first_zeta_star_time = None if math.isnan(first) else float(first)

    def track(self):
        """Between history rows (runner, history_every > 1): only what summary.json reports
        over all steps, the maximal interpenetration and the first time the probe reaches
        zeta_star (in serial no communication)."""
        self.contact.track(self.u, self.t)
        if self.probe.point is not None:
            self.probe(self.zeta, self.t, self.params.zeta_star)

    def initial_damage(self):
        """Example 2 selects its initial damage with ``--set initial_damage=a|b``."""
        choices = self.data.builders.get("zeta0")
        choice = self.params.extra.get("initial_damage")
        if choices is not None:
            if choice not in choices:
                raise InputError(f"initial_damage must be one of {', '.join(choices)}, "
                                 f"got {choice!r}")
            self.data.zeta0 = choices[choice]
        self.interpolate_zeta0(self.zeta)

    def update_output(self):
        compat.interpolate(self.von_mises, self._vm_expr)

    # -- stability of the explicit elastic and contact forces (docs/models.md, section 3.3)
    def _stability_check(self, V, x, dsC) -> dict:
        """k_max of the explicit scheme (undamaged body, Gamma_C fully in contact: conservative)
        compared with k according to ``stability_check``; {} when off. The implicit variant
        (elastic_term = implicit) is reported against the same k_max but never warned about."""
        action = x.get("stability_check", "warn")
        if action == "off":
            return {}
        from damage_dolfinx.numerics.stability import checked, estimate_stability
        start = time.perf_counter()
        has_contact = self.comm.allreduce(
            int(np.sum(self.data.geometry.facet_tags.values == GAMMA_C)), op=MPI.SUM) > 0
        out = estimate_stability(V, self.params.E, self.params.nu, self.rho, self.m_visc,
                                 c_nu=self.c_nu if has_contact else 0.0, dsC=dsC, bcs=self.bcs,
                                 normal=self.n_facet, k=self.k)
        checked(out, self.k,
                f"{self.data.id}: explicit elastic and contact forces, eigenvalue estimate",
                action=action if self.elastic_term == "explicit" else "off")
        out["time_s"] = time.perf_counter() - start
        return out

    # -- scalars and summary
    def scalars(self) -> dict:
        """The base scalars (the same operations as Model.scalars, so the same values) plus
        v_L2, the interpenetration and the probe; the sums and extrema in one reduction (none
        in serial). Each row's products are its own (M u_n directly, not carried by (3.160)
        from the previous row), so that a history cadence gives the same rows bit for bit."""
        norms = self.field_norms()
        parts = norms.u_parts() + [norms.mass_parts(self.v)]
        zeta_integral, lo, hi = norms.zeta_parts()
        (u_L2_sq, eps_sq, v_sq, zeta_integral), (neg_min, zeta_max) = \
            bookkeeping.sums_and_maxima(self.comm, parts + [zeta_integral], [-lo, hi])
        out = {"u_L2": float(np.sqrt(max(u_L2_sq, 0.0))),
               "eps_u_L2": float(np.sqrt(max(eps_sq, 0.0))),
               "zeta_min": -neg_min, "zeta_max": zeta_max,
               "zeta_mean": float(zeta_integral / norms.area),
               "v_L2": float(np.sqrt(abs(v_sq)))}  # = ||v||_L2: v^T M v, no assembly
        out.update(self.contact(self.u, self.t))
        out.update(self.probe(self.zeta, self.t, self.params.zeta_star))
        return out

    def summary_extra(self) -> dict:
        out = {"k": self.k, "elastic_term": self.elastic_term + (
            "" if self.elastic_term == "explicit" else " (our option, not the thesis scheme)")}
        if self.stability:
            out.update(k_max=self.stability["k_max"], k_over_k_max=self.stability["k_over_k_max"],
                       k_max_lower_bound=self.stability.get("k_max_lower_bound"),
                       stability=self.stability)
        out.update(self.contact.summary())
        out.update(self.probe.summary())
        out.update(self.profiles.summary(self.zeta, self.t))
        return out

    def contact_pressure(self):
        """eta_*(zeta_n) c_nu (u_n.nu - gap)_+ on Gamma_C (3.116)."""
        from damage_dolfinx.forms.fully_damageable import damaged_contact_pressure
        return damaged_contact_pressure(self.u, self.zeta, self.n_facet, self.c_nu, self.gap,
                                        self.params.zeta_star)

    def iteration_totals(self) -> dict:
        out = {"damage_snes": self.damage.iterations if self.damage else 0}
        if self.elastic_term == "explicit":
            out.update(mech_ksp=self.mech.iterations, mech_solves=self.mech.solves)
        else:
            out.update(snes=self.mech.iterations, mech_ksp=self.mech.linear_iterations)
        return out
