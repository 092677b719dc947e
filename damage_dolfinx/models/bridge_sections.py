"""Cross-sections of the masonry ring (Section 2.1 Example 3 and its 3-D vault): which ring
node lies on which section, the section statistics (max / min zeta, section damage D_j, the
intrados and extrados values), the rotation of each cross-section, and the hinges.

Hinges (the mechanism, thesis Figures 2.8-2.9): the sections where damage localises. For every
section the *section damage* D_j = 1 - mean of eta_*(zeta_n) over its nodes is the average
stiffness loss across the ring (0 sound, 1 - zeta_star failed). A hinge is a peak of D_j along
the ring (scipy.signal.find_peaks, the ring ends padded with D = 0 so that a springing can be a
peak) of height >= ``hinge_damage`` (default 0.3) and prominence >= ``hinge_prominence``
(default 0.2), peaks closer than ``hinge_separation`` (default: one ring thickness) merged. For
each hinge the face with the lower zeta (intrados or extrados) is reported: with tension-only
damage that is the face that opens. The thresholds are conventions, not calibrated to a count.

Mechanism: a peak of D_j marks damage, not motion (self weight alone leaves four symmetric
peaks). The rotation of each cross-section is taken as the least-squares slope d u_t/d r of
the tangential displacement across it (``section_rotation``); a hinge's rotation in the collapse
step is the jump of that slope across +- one hinge separation. A hinge belongs to the mechanism
if it rotates by at least ``hinge_rotation`` (default 0.2) x the largest hinge rotation; its
opening face is the extrados if the jump is positive, the intrados otherwise.

:class:`RingSections` is a mixin of :class:`~damage_dolfinx.models.bridge_2_1.BridgeDamage`:
it reads the stepper's fields (``zeta``, ``u``), ``comm``, ``params``, ``data.geometry`` and
the ``bridge`` parameters.
"""
from __future__ import annotations

import numpy as np
from mpi4py import MPI

from damage_dolfinx.core.parameters import InputError


def _allreduce(comm, array: np.ndarray, op) -> np.ndarray:
    """Element-wise reduction of a per-section array over all ranks (buffer interface)."""
    out = np.ascontiguousarray(array).copy()
    comm.Allreduce(MPI.IN_PLACE, out, op=op)
    return out


class RingSections:
    """Sections, section statistics, rotations and hinges of the ring."""

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
