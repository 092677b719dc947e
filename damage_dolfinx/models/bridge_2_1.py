"""Section 2.1 Example 3: collapse of a masonry arch ring (scheme (2.20)-(2.21) of
:class:`ElasticDamage`, plus the load history, the failure criterion and the hinges).

Loads (our defaults, docs/models.md, section 2.1-collapse): self weight f_B = (0, -rho g) from t =
0 and a vertical load P(t) = load_rate * t [kN per metre of out-of-plane thickness] at quarter
span, applied as the uniform traction f_N = (0, -P(t)/|Gamma_N|) on the load patch Gamma_N (so that
its resultant is exactly P whatever the mesh).

Failure (thesis, Section 2.1 Example 3): "collapse occurs at the loading step for which a whole
cross-section of the bridge reaches the lower bound for the damage zeta_*". A cross-section is a
radial grid line j of the ring (n_r + 1 nodes on the structured mesh; on an unstructured mesh the
nodes whose polar angle is nearest to theta_j); it has failed when the maximum of zeta_n over
its nodes is <= zeta_star (+ ZETA_STAR_TOL). The failure load is P(t_n) at the first such step n.

Damage bound (``damage_bound``): with the thesis data the source violates the sign
condition (2.11) (thesis lines 752-758: phi >= 0 for zeta <= zeta_star would need
lam_D (1 - zeta_star)/zeta_star = 0.198 >= 0.5 lam_u |eps^+-|^2, i.e. strains below 9e-6), so the
linear step (2.20) drives zeta_n far below zeta_star (-1200 at h = 0.05 before collapse) and the
diffusion spreads the undershoot. The thesis keeps zeta in [zeta_star, 1]: Theorem 2.1 (line 814),
the truncation eta_* onto [zeta_star, 1] (lines 359-361, (2.2)-(2.3) lines 718-720), and for the
bridge "a whole cross-section reaches the lower bound for the damage zeta_star" (line 1123), which
needs nodes that reach zeta_star and stay there while the run goes on. "obstacle" (default)
solves each step (2.20) as the obstacle problem over K^h = {zeta_star <= zeta <= 1} (the discrete
problem (2.96), line 1566, of the other sections, whose bound and reason are lines 1154-1172),
with the Section 2.1 source unchanged; it equals (2.20) wherever the linear step stays in
[zeta_star, 1]. "clamp" truncates the nodal values of the linear step, zeta_n <- eta_*(zeta_n):
with the consistent mass matrix it leaves checkerboard oscillations in the damaged zones.
"none" is the literal linear step (2.20). The damage figures are drawn on [zeta_star, 1]
(figstyle; a field that leaves it widens the scale and prints its extremes).

The step is 2.1's, the package's generic one (models/base.py), with the damage sub-step of
``damage_bound``; the failure record (the first failed section, the hinges, the running minimum
of zeta) is kept after each step by ``scalars`` and ``stop_reason``, not inside the step, and is
not checkpointed (``checkpoint_supported`` is False).

Hinges and the mechanism: bridge_sections.py (section damage D_j, its peaks, the rotation of
each cross-section and which hinges move at collapse).

3-D (the barrel vault of geometries/vault.py, example 2.1-ex3-vault): the dimension
comes from the mesh. The ring is extruded along z by a width W; P is a line load per metre of
width on the extruded load strip (traction 1000 P / L_N, L_N = strip area / W, so the total load
is P W); self weight (0, -rho g, 0). A cross-section is the plane theta = theta_j (grid line j
times the width) and everything above is computed over its nodes: collapse when all of them reach
zeta_star, D_j the mean over the plane, the rotation the slope fitted to all its nodes (every grid
layer has the same radii, so this is the mean over the width). A hinge *line* is a peak of D_j;
per hinge the spread across the width (D and the rotation per grid layer) is reported, and at
collapse the summary keeps D per (section, layer) and zeta on the unrolled intrados and extrados
(hinge_lines.py draws them). 2-D runs are unchanged (bit for bit).
"""
from __future__ import annotations

import dataclasses
import math
from typing import Optional

import numpy as np
import ufl
from dolfinx import fem

from damage_dolfinx import compat
from damage_dolfinx.forms.constitutive import eps
from damage_dolfinx.numerics.damage import DamageStep
from damage_dolfinx.core.tags import GAMMA_N
from damage_dolfinx.core.parameters import InputError, ModelParameters
from damage_dolfinx.models.bridge_sections import RingSections
from damage_dolfinx.models.elastic_2_1 import ElasticDamage

#: problem-specific parameters (ModelParameters.extra) and their defaults
BRIDGE_DEFAULTS = {
    "rho": 2200.0,           # density [kg/m^3]
    "gravity": 9.81,         # [m/s^2]; self weight f_B = (0, -rho*gravity); 0 switches it off
    "load_rate": 1000.0,     # dP/dt [kN/s] of the quarter-span load (per metre of thickness);
                             # our default; catalogue example 2.1-ex3 uses the calibrated 4500
    "hinge_damage": 0.3,     # a hinge is a peak of the section damage D_j of at least this height
    "hinge_prominence": 0.2,  # ... standing out by at least this much (scipy find_peaks)
    "hinge_separation": 0.0,  # merge peaks closer than this [m]; 0 = one ring thickness
    "hinge_rotation": 0.2,   # a hinge belongs to the mechanism if it rotates in the collapse
                             # step by at least this fraction of the largest hinge rotation
    "damage_bound": "obstacle",  # keep zeta_n in [zeta_star, 1] (module docstring): "obstacle",
                                 # "clamp", or "none" (the literal linear step (2.20))
}

#: values of ``damage_bound``
DAMAGE_BOUNDS = ("obstacle", "clamp", "none")

#: a section has failed when max zeta_n over its nodes <= zeta_star + ZETA_STAR_TOL (the bound
#: is met to solver round-off)
ZETA_STAR_TOL = 1e-9


def check_bridge_parameters(extra: dict):
    """Refuse invalid bridge data (InputError) before any work."""
    rules = {"rho": (lambda v: v > 0, "(density) must be positive"),
             "gravity": (lambda v: v >= 0, "must be >= 0 (0: no self weight)"),
             "load_rate": (lambda v: v >= 0, "(kN/s) must be >= 0"),
             "hinge_damage": (lambda v: 0 < v < 1, "must lie in (0, 1)"),
             "hinge_prominence": (lambda v: 0 <= v < 1, "must lie in [0, 1)"),
             "hinge_separation": (lambda v: v >= 0, "(m) must be >= 0"),
             "hinge_rotation": (lambda v: 0 <= v <= 1, "must lie in [0, 1]")}
    bound = extra.get("damage_bound", BRIDGE_DEFAULTS["damage_bound"])
    if bound not in DAMAGE_BOUNDS:
        raise InputError(f"damage_bound must be one of {', '.join(DAMAGE_BOUNDS)}, got "
                         f"damage_bound = {bound!r}")
    for name, (ok, text) in rules.items():
        value = extra.get(name, BRIDGE_DEFAULTS[name])
        if not isinstance(value, (int, float)) or not math.isfinite(value) or not ok(value):
            raise InputError(f"{name} {text}, got {name} = {value!r}")


class _ClampedStep:
    """The linear step (2.20) followed by the nodal truncation zeta_n <- eta_*(zeta_n)."""

    def __init__(self, step, zeta_star: float):
        self.step, self.zeta, self.zeta_star = step, step.zeta, zeta_star

    def solve(self) -> int:
        its = self.step.solve()
        np.clip(self.zeta.x.array, self.zeta_star, 1.0, out=self.zeta.x.array)
        return its

    @property
    def iterations(self) -> int:
        return self.step.iterations


class BridgeDamage(RingSections, ElasticDamage):
    """Problem VP^{hk} of Section 2.1 on the arch ring, with the collapse criterion."""

    id = "2.1-collapse"
    title = "quasistatic elastic masonry under a growing load, to collapse"
    contact_roles = ()
    checkpoint_supported = False  # the failure record and hinge list are not saved

    history_columns = ("P_kN", "u_load_y", "weakest_section", "weakest_section_zeta_max",
                       "n_hinges")

    @classmethod
    def defaults(cls) -> ModelParameters:
        return dataclasses.replace(ElasticDamage.defaults(), stop_at_zeta_star=False,
                                   extra=dict(BRIDGE_DEFAULTS))

    @classmethod
    def check(cls, params: ModelParameters) -> ModelParameters:
        check_bridge_parameters(params.extra)
        return params

    def __init__(self, data, **kwargs):
        geo = data.geometry
        if not hasattr(geo, "section_index"):
            raise InputError("example 2.1-ex3 needs the arch geometry (geometries/bridge.py); "
                             "external --mesh files are not supported")
        extra = {**BRIDGE_DEFAULTS, **data.params.extra}
        check_bridge_parameters(extra)
        self.bridge = extra
        self.width = float(getattr(geo, "width", 1.0))  # 2-D: unit out-of-plane thickness
        super().__init__(data, **kwargs)
        if self.mesh.topology.dim == 3:
            self._lagged_direct_mech()
        self._bound_damage(kwargs.get("damage_prefix", "damage_"))
        self._setup_sections(geo)
        self._patch_uy = compat.form(self.u[1] * self._dsN)
        self.failure: Optional[dict] = None
        self._hinges = []
        self.zeta_min_run = float("inf")  # min over nodes and steps of zeta_n

    def _lagged_direct_mech(self):
        """3-D vault: the elasticity by CG on a lagged LU factorisation (the 2-D default) instead
        of scalable.py's CG + GAMG: at nu = 0.49 GAMG needs many CG iterations per step and broke
        down near collapse (DIVERGED_INDEFINITE_PC, W = 1 m, h = 0.1); lagged LU is several times
        faster per step at that size (benchmarks/README.md, "Why the defaults"). -mech_pc_type
        gamg (with the other -mech_* options) still selects AMG."""
        from damage_dolfinx.numerics import scalable
        from damage_dolfinx.numerics.solvers import LAGGED_DIRECT, LinearSolver
        from damage_dolfinx.models.elastic_2_1 import MECH_REFACTOR_ITS
        old = self.mech
        self.mech = LinearSolver(old.a, old.L, old.bcs, old.prefix, self.context,
                                 defaults=LAGGED_DIRECT, refactor_after_its=MECH_REFACTOR_ITS)
        scalable.prepare_mech(self.mech, self.u.function_space)
        old.ksp.destroy()

    def _bound_damage(self, prefix):
        """Replace the linear damage step (2.20) by one that keeps zeta_n in [zeta_star, 1]
        (``damage_bound``, module docstring); "none" keeps the literal step."""
        p, bound = self.params, self.bridge["damage_bound"]
        if bound == "obstacle":
            phi_old = self.damage_source(eps(self.u), self.zeta_old)
            self.damage = DamageStep(self.zeta, self.zeta_old, phi_old, self.k, self.kappa,
                                     self.context, obstacle=True, zeta_star=p.zeta_star,
                                     prefix=prefix)
        elif bound == "clamp":
            self.damage = _ClampedStep(self.damage, p.zeta_star)

    # -- loads (docs/models.md, section 2.1-collapse)
    def loads(self):
        """f_B = (0, -rho g[, 0]), f_N = (0, -1000 P(t)/L_N[, 0]) N/m^2 with P(t) = load_rate t
        kN (per metre of width) and L_N the patch length (in 3-D the strip's area / width)."""
        msh = self.mesh
        gdim = msh.topology.dim
        msh.topology.create_connectivity(gdim - 1, gdim)
        self._dsN = ufl.Measure("ds", domain=msh, subdomain_data=self.data.geometry.facet_tags)(GAMMA_N)
        self.patch_measure = compat.assemble_scalar(fem.Constant(msh, 1.0) * self._dsN, self.comm)
        if not self.patch_measure > 0:
            raise InputError("the arch mesh has no load patch (facet tag GAMMA_N)")
        self.patch_length = self.patch_measure / self.width
        weight = self.bridge["rho"] * self.bridge["gravity"]
        zero = (0.0,) * (gdim - 2)  # the width direction z of the 3-D vault
        # fem.Constants (not floats) so that a zero load still gives a well-formed UFL form
        f_B = fem.Constant(msh, np.array([0.0, -weight, *zero], dtype=compat.ScalarType))
        rate = fem.Constant(msh, 1000.0 * self.bridge["load_rate"] / self.patch_length)
        f_N = ufl.as_vector((0.0, -rate * self.t_const, *zero))
        return f_B, f_N

    def load_kN(self, t=None) -> float:
        """P(t) in kN (per metre of out-of-plane thickness)."""
        return round(self.bridge["load_rate"] * (self.t if t is None else t), 9)

    def iteration_totals(self) -> dict:
        out = super().iteration_totals()
        if self.bridge["damage_bound"] == "obstacle":  # the damage step is a VI: Newton its
            out["snes"] = out.pop("damage_ksp")
        return out

    # -- runner hooks
    def scalars(self) -> dict:
        """Base scalars plus load, displacement under the load, weakest section, hinges; detects
        collapse (a section with max zeta_n <= zeta_star)."""
        out = super().scalars()
        stats = self.section_stats()
        if self.n != self._phi_n:  # rotation increment of the last step (once per step)
            phi = self.section_rotation()
            self._dphi = phi - (phi if self._phi_prev is None else self._phi_prev)
            self._phi_prev, self._phi_n = phi, self.n
            if self._n_layers > 1:
                phi_l = self.layer_rotation()
                prev = getattr(self, "_phi_prev_layers", None)
                self._dphi_layers = phi_l - (phi_l if prev is None else prev)
                self._phi_prev_layers = phi_l
        weakest = int(np.argmin(stats["zeta_max"]))
        hinges = self.hinges(stats)
        self._hinges = hinges
        u_y = compat.assemble_scalar(self._patch_uy, self.comm) / self.patch_measure
        self.zeta_min_run = min(self.zeta_min_run, float(stats["zeta_min"].min()))
        out.update(P_kN=self.load_kN(), u_load_y=u_y, weakest_section=weakest,
                   weakest_section_zeta_max=float(stats["zeta_max"][weakest]),
                   n_hinges=len(hinges))
        failed = np.flatnonzero(stats["zeta_max"] <= self.params.zeta_star + ZETA_STAR_TOL)
        if failed.size and self.failure is None and self.n > 0:
            pts = self.data.geometry.section_points(failed)
            self.failure = {"step": self.n, "t": self.t, "P_kN": self.load_kN(),
                            "u_load_y": u_y, "sections": failed.tolist(),
                            "section_damage": np.round(stats["damage"], 4).tolist(),
                            "s_m": np.round(pts["s"], 4).tolist(),
                            "angle_deg": np.round(pts["angle_deg"], 3).tolist()}
            if self._n_layers > 1:  # 3-D: for the hinge-line maps (hinge_lines.py)
                from damage_dolfinx.viz.hinge_lines import face_maps
                z_in, z_out = face_maps(self)
                self.failure.update(
                    zeta_intrados=np.round(z_in, 4).tolist(),
                    zeta_extrados=np.round(z_out, 4).tolist(),
                    section_damage_layers=np.round(stats["damage_layers"], 4).tolist(),
                    section_rotation_step_mrad=np.round(1e3 * self._dphi, 6).tolist())
        return out

    def stop_reason(self) -> Optional[str]:
        if self.failure is not None:
            return "collapse"
        return super().stop_reason()

    def summary_extra(self) -> dict:
        out = self._summary_2d()
        if self._n_layers > 1:  # the 3-D vault: loads per metre of width, hinge lines
            from damage_dolfinx.viz.hinge_lines import vault_summary
            out["vault"] = vault_summary(self)
        return out

    def draw_figure(self, fig, path):
        """A catalogue figure of kind "problem" (hinge_lines.draw_figure)."""
        from damage_dolfinx.viz.hinge_lines import draw_figure
        draw_figure(self, fig, path)

    def _summary_2d(self) -> dict:
        geo = self.data.geometry
        f = self.failure
        hinges = self._hinges
        return {
            "failure_load_kN": None if f is None else f["P_kN"],
            "failure_time": None if f is None else f["t"],
            "failure_step": None if f is None else f["step"],
            "failed_sections": None if f is None else
            [{"section": j, "s_m": s, "angle_deg": a}
             for j, s, a in zip(f["sections"], f["s_m"], f["angle_deg"])],
            "failure_u_load_y": None if f is None else f["u_load_y"],
            "failure_section_damage": None if f is None else f["section_damage"],
            "load_increment_kN": self.bridge["load_rate"] * self.data.time.k,
            "damage_bound": self.bridge["damage_bound"], "zeta_min_run": self.zeta_min_run,
            "hinges": hinges, "n_hinges": len(hinges),
            "n_mechanism_hinges": sum(h["mechanism"] for h in hinges),
            "hinge_definition": {"section_damage": "D_j = 1 - mean eta_*(zeta) over section j",
                                 "min_height": self.bridge["hinge_damage"],
                                 "min_prominence": self.bridge["hinge_prominence"],
                                 "min_separation_m": self.hinge_separation(),
                                 "mechanism": "rotation in the collapse step >= "
                                 f"{self.bridge['hinge_rotation']} x the largest (jump of the "
                                 "section rotation d u_t/d r across +- one separation); opening "
                                 "face: extrados if the jump is positive"},
            "bridge": {"load_rate_kN_per_s": self.bridge["load_rate"],
                       "self_weight_N_per_m3": self.bridge["rho"] * self.bridge["gravity"],
                       "x_load_m": geo.x_load, "patch_length_m": self.patch_length,
                       "n_r": geo.n_r, "n_theta": geo.n_theta, "structured": geo.structured,
                       "nodes_per_section": [int(self.section_nodes.min()),
                                             int(self.section_nodes.max())],
                       "r_in": geo.r_in, "r_out": geo.r_out, **geo.options},
        }
