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

Damage bound (issue 16; ``damage_bound``): with the thesis data the source violates the sign
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

Hinges (the mechanism, thesis Figures 2.8-2.9): the sections where damage localises. For every
section the *section damage* D_j = 1 - mean of eta_*(zeta_n) over its nodes is the average
stiffness loss across the ring (0 sound, 1 - zeta_star failed). A hinge is a peak of D_j along
the ring (scipy.signal.find_peaks, the ring ends padded with D = 0 so that a springing can be a
peak) of height >= ``hinge_damage`` (default 0.3) and prominence >= ``hinge_prominence``
(default 0.2), peaks closer than ``hinge_separation`` (default: one ring thickness) merged. For
each hinge the face with the lower zeta (intrados or extrados) is reported: with tension-only
damage that is the face that opens. The thresholds are conventions, not calibrated to a count.

Mechanism: a peak of D_j marks damage, not motion (self weight alone leaves four symmetric
peaks). The rotation of each cross-section is measured as the least-squares slope d u_t/d r of
the tangential displacement across it (``section_rotation``); a hinge's rotation in the collapse
step is the jump of that slope across +- one hinge separation. A hinge belongs to the mechanism
if it rotates by at least ``hinge_rotation`` (default 0.2) x the largest hinge rotation; its
opening face is the extrados if the jump is positive, the intrados otherwise.

3-D (issue 17, the barrel vault of geometries/vault.py, example 2.1-ex3-vault): the dimension
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

import math
from typing import Optional

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from damage_dolfinx import compat
from damage_dolfinx.numerics.constitutive import eps
from damage_dolfinx.numerics.damage import DamageStep
from damage_dolfinx.geometries import GAMMA_N
from damage_dolfinx.parameters import InputError
from damage_dolfinx.models.base import ProblemData
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


def _allreduce(comm, array: np.ndarray, op) -> np.ndarray:
    """Element-wise reduction of a per-section array over all ranks (buffer interface)."""
    out = np.ascontiguousarray(array).copy()
    comm.Allreduce(MPI.IN_PLACE, out, op=op)
    return out


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


class BridgeDamage(ElasticDamage):
    """Problem VP^{hk} of Section 2.1 on the arch ring, with the collapse criterion."""

    checkpoint_supported = False  # the failure record and hinge list are not saved

    extra_history_columns = ["P_kN", "u_load_y", "weakest_section", "weakest_section_zeta_max",
                             "n_hinges"]

    def __init__(self, data: ProblemData, **kwargs):
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
        of scalable.py's CG + GAMG: at nu = 0.49 GAMG needed 100-140 CG iterations per step and
        broke down near collapse (DIVERGED_INDEFINITE_PC at step 30, W = 1 m, h = 0.1); lagged
        LU is about 4x faster per step at that size (40 000 dofs). -mech_pc_type gamg (with
        the other -mech_* options) still selects AMG."""
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

    # -- cross-sections of the ring
    def _setup_sections(self, geo):
        """Section index of every owned ring node of the damage space, and the global count of
        nodes per section (n_r + 1 on the structured grid)."""
        Z = self.zeta.function_space
        n_owned = Z.dofmap.index_map.size_local
        x = Z.tabulate_dof_coordinates()[:n_owned]
        j = geo.section_index(x)
        keep = geo.in_ring(x) & (j >= 0) & (j <= geo.n_theta)
        self._sec_dofs = np.flatnonzero(keep).astype(np.int32)
        self._sec_j = j[keep]
        r, theta = geo.polar(x[keep])
        ns = geo.n_theta + 1
        # section rotation (``section_rotation``): the vector P1 space has the scalar layout
        V = self.u.function_space
        if not np.allclose(V.tabulate_dof_coordinates()[:n_owned], x):
            raise RuntimeError("vector and scalar P1 dof layouts differ")
        self._sec_r = r
        self._sec_tangent = np.stack([np.sin(theta), -np.cos(theta)], axis=1)  # left -> right
        self._phi_prev, self._phi_n = None, None
        self._dphi = np.zeros(ns)
        count = np.bincount(self._sec_j, minlength=ns).astype(np.int64)
        self.section_nodes = _allreduce(self.comm, count, MPI.SUM)
        # 3-D vault: key j * n_layers + l of (section, grid layer across the width): hinge lines
        self._n_layers = geo.n_width + 1 if hasattr(geo, "layer_index") else 1
        self._sec_jl = self._sec_j * self._n_layers + (
            geo.layer_index(x[keep]) if self._n_layers > 1 else 0)
        self._layer_nodes = _allreduce(self.comm, np.bincount(
            self._sec_jl, minlength=ns * self._n_layers).astype(np.int64), MPI.SUM)
        self._dphi_layers = np.zeros((ns, self._n_layers))
        # intrados / extrados node of each section (face of the first damage)
        tol = 1e-6 * geo.r_out
        self._on_in = np.abs(r - geo.r_in) < tol
        self._on_out = np.abs(r - geo.r_out) < tol
        if self.section_nodes.min() < 2:
            raise InputError(f"mesh too coarse for the section criterion: a section of the ring "
                             f"has {self.section_nodes.min()} node(s)")

    def section_stats(self) -> dict:
        """Per section j = 0..n_theta (global, on every rank): max and min of zeta_n, section
        damage D_j = 1 - mean eta_*(zeta_n), zeta_n at the intrados and extrados nodes."""
        ns = self.data.geometry.n_theta + 1
        z = self.zeta.x.array[self._sec_dofs]
        j = self._sec_j
        zmax, zmin = np.full(ns, -np.inf), np.full(ns, np.inf)
        np.maximum.at(zmax, j, z)
        np.minimum.at(zmin, j, z)
        eta = np.clip(z, self.params.zeta_star, 1.0)
        eta_sum = np.bincount(j, weights=eta, minlength=ns)
        z_in, z_out = np.full(ns, np.inf), np.full(ns, np.inf)
        np.minimum.at(z_in, j[self._on_in], z[self._on_in])
        np.minimum.at(z_out, j[self._on_out], z[self._on_out])
        c = self.comm
        out = {"zeta_max": _allreduce(c, zmax, MPI.MAX), "zeta_min": _allreduce(c, zmin, MPI.MIN),
               "damage": 1.0 - _allreduce(c, eta_sum, MPI.SUM) / self.section_nodes,
               "zeta_intrados": _allreduce(c, z_in, MPI.MIN),
               "zeta_extrados": _allreduce(c, z_out, MPI.MIN)}
        if self._n_layers > 1:  # 3-D: D per (section, layer across the width)
            nl = self._n_layers
            eta_jl = np.bincount(self._sec_jl, weights=eta, minlength=ns * nl)
            out["damage_layers"] = (1.0 - _allreduce(c, eta_jl, MPI.SUM)
                                    / self._layer_nodes).reshape(ns, nl)
        return out

    def section_rotation(self) -> np.ndarray:
        """Per section j (global): least-squares slope d u_t/d r of the tangential displacement
        across the section, i.e. minus the rotation of the cross-section [rad]. Its jumps
        between sections are the hinge rotations of the mechanism. In 3-D the fit pools all
        nodes of the section plane; every grid layer has the same radii, so it is the mean of
        the layers' slopes (the rotation averaged over the width)."""
        return self._slopes(self._sec_j, self.data.geometry.n_theta + 1)

    def layer_rotation(self) -> np.ndarray:
        """3-D: the slope of ``section_rotation`` per (section j, grid layer l), shape (ns, nl)."""
        ns, nl = self.data.geometry.n_theta + 1, self._n_layers
        return self._slopes(self._sec_jl, ns * nl).reshape(ns, nl)

    def _slopes(self, key, n_keys) -> np.ndarray:
        u = self.u.x.array.reshape(-1, self.mesh.topology.dim)[self._sec_dofs, :2]
        ut = np.sum(u * self._sec_tangent, axis=1)
        r = self._sec_r
        sums = np.stack([np.bincount(key, weights=w, minlength=n_keys)
                         for w in (np.ones_like(r), r, ut, r * r, r * ut)])
        n, sr, su, srr, sru = _allreduce(self.comm, sums, MPI.SUM)
        return (n * sru - sr * su) / (n * srr - sr * sr)

    def hinge_separation(self) -> float:
        geo = self.data.geometry
        return self.bridge["hinge_separation"] or (geo.r_out - geo.r_in)

    def hinges(self, stats: dict) -> list:
        """Peaks of the section damage D_j (module docstring); each with section index, centre-
        line abscissa s from the left springing, angle, position, D_j and the damaged face."""
        from scipy.signal import find_peaks
        geo = self.data.geometry
        D = stats["damage"]
        rc = 0.5 * (geo.r_in + geo.r_out)
        distance = max(1, int(round(self.hinge_separation() / (rc * geo.dtheta))))
        peaks, _ = find_peaks(np.concatenate([[0.0], D, [0.0]]), height=self.bridge["hinge_damage"],
                              prominence=self.bridge["hinge_prominence"], distance=distance)
        j = peaks - 1
        pts = geo.section_points(j)
        face = np.where(stats["zeta_intrados"][j] < stats["zeta_extrados"][j], "intrados", "extrados")
        # rotation of each hinge in the last step: jump of the section rotation across +- one
        # hinge separation, relative to the largest one (which hinges move at collapse)
        n_last = self._dphi.size - 1
        rot = np.array([self._dphi[min(jj + distance, n_last)] - self._dphi[max(jj - distance, 0)]
                        for jj in j])
        rel = np.abs(rot) / max(np.abs(rot).max(), 1e-300) if rot.size else rot
        out = [{"section": int(j[i]), "s_m": round(float(pts["s"][i]), 4),
                 "rotation_step_mrad": round(1e3 * float(rot[i]), 6),
                 "rotation_step_relative": round(float(rel[i]), 3),
                 "mechanism": bool(rel[i] >= self.bridge["hinge_rotation"]),
                 "opening_face": "extrados" if rot[i] > 0 else "intrados",
                 "angle_deg": round(float(pts["angle_deg"][i]), 3),
                 "x_m": round(float(pts["x"][i]), 4), "y_m": round(float(pts["y"][i]), 4),
                 "section_damage": round(float(D[j[i]]), 4), "zeta_max": float(stats["zeta_max"][j[i]]),
                 "damaged_face": str(face[i])} for i in range(j.size)]
        if self._n_layers > 1:  # 3-D: the hinge line across the width, layer by layer
            for h, jj in zip(out, j):
                D_l = stats["damage_layers"][jj]
                rot_l = (self._dphi_layers[min(jj + distance, n_last)]
                         - self._dphi_layers[max(jj - distance, 0)])
                h.update(width_damage_min=round(float(D_l.min()), 4),
                         width_damage_max=round(float(D_l.max()), 4),
                         width_fraction_damaged=round(float(np.mean(
                             D_l >= self.bridge["hinge_damage"])), 4),
                         rotation_step_mrad_width=[round(1e3 * float(rot_l.min()), 6),
                                                   round(1e3 * float(rot_l.max()), 6)])
        return out

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
