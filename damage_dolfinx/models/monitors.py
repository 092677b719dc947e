"""Monitors of the Section 3.3 runs (fully_damageable_3_3.py): the maximal interpenetration on
Gamma_C and its location (ContactMonitor; its running maximum over all steps is tracked at every
step, also between history rows, and kept in the checkpoint), zeta at a probe point (ZetaProbe)
and damage profiles along a grid line (DamageProfiles)."""
from __future__ import annotations

import math

import numpy as np
from mpi4py import MPI

from damage_dolfinx import compat
from damage_dolfinx.core.parameters import InputError


class ContactMonitor:
    """Maximal interpenetration (u.nu - gap)_+ over the vertices of Gamma_C (u is P1, so the
    maximum over a facet is at a vertex), with nu the outward normal of each facet, and its
    location; the running maximum over the run goes to summary.json. Any dimension: a 3-D
    facet is a triangle, its normal the cross product of two edges (columns get x3)."""

    def __init__(self, V, tags, tag, gap):
        self.comm, self.gap = V.mesh.comm, gap
        msh = V.mesh
        tdim = d = msh.topology.dim
        self.columns = ["penetration_max"] + [f"penetration_x{i + 1}" for i in range(d)]
        for dim in ((tdim, 0), (tdim - 1, 0), (tdim - 1, tdim)):
            msh.topology.create_connectivity(*dim)
        facets = tags.indices[tags.values == tag]
        c2v = msh.topology.connectivity(tdim, 0)
        cell_dofs = compat.cell_dofs(V)  # owned cells; P1: the cell's dofs follow its vertices
        nc, nv = cell_dofs.shape
        cell_vertices = c2v.array.reshape(-1, nv)[:nc]
        v2d = np.full(msh.topology.index_map(0).size_local + msh.topology.index_map(0).num_ghosts,
                      -1, dtype=np.int64)
        v2d[cell_vertices] = cell_dofs
        f2v, f2c = msh.topology.connectivity(tdim - 1, 0), msh.topology.connectivity(tdim - 1, tdim)
        cells = f2c.array[f2c.offsets[facets]]  # exterior facets: their only cell
        keep = cells < nc  # a facet of a ghost cell is monitored by the rank owning that cell
        facets, cells = facets[keep], cells[keep]
        self.dofs = v2d[f2v.array.reshape(-1, d)[facets]]            # (nf, d) vertex dofs
        X = V.tabulate_dof_coordinates()[:, :d]
        self.X = X[self.dofs]                                          # (nf, d, d)
        cell_mid = X[v2d[cell_vertices[cells]]].mean(axis=1)
        if d == 2:
            t = self.X[:, 1] - self.X[:, 0]
            n = np.stack([t[:, 1], -t[:, 0]], axis=1) / np.linalg.norm(t, axis=1)[:, None]
        else:  # triangle: normal of its plane (the sign is fixed below)
            n = np.cross(self.X[:, 1] - self.X[:, 0], self.X[:, 2] - self.X[:, 0])
            n = n / np.linalg.norm(n, axis=1)[:, None]
        outward = np.einsum("ij,ij->i", n, self.X.mean(axis=1) - cell_mid) > 0
        self.normal = np.where(outward[:, None], n, -n)
        self.present = self.comm.allreduce(int(facets.size), op=MPI.SUM) > 0
        self.d = d
        # (u.nu - gap) at the facet vertices, facet by facet, from flat views (the
        # per-step track() costs a few NumPy operations on the Gamma_C dofs)
        flat = self.dofs.reshape(-1)
        self._index = [flat * d + c for c in range(d)]
        self._normal = [np.repeat(self.normal[:, c], d) for c in range(d)]
        self._at = self.X.reshape(-1, d)
        self.worst = {"max_penetration": 0.0, "max_penetration_t": 0.0,
                      "max_penetration_at": [math.nan] * d}

    def _penetration(self, u) -> np.ndarray:
        """u.nu - gap at every (facet, vertex) pair of this rank, facet-major."""
        a = u.x.array
        pen = a[self._index[0]] * self._normal[0]
        for index, normal in zip(self._index[1:], self._normal[1:]):
            pen += a[index] * normal
        return pen - self.gap

    def _best(self, pen) -> tuple:
        if not pen.size:
            return (-np.inf,) + (math.nan,) * self.d
        i = int(np.argmax(pen))
        return (float(pen[i]), *map(float, self._at[i]))

    def _keep(self, value, t, at):
        if value > self.worst["max_penetration"]:
            self.worst = {"max_penetration": value, "max_penetration_t": t,
                          "max_penetration_at": list(at)}

    def __call__(self, u, t) -> dict:
        if not self.present:
            return {}
        best = self._best(self._penetration(u))
        candidates = self.comm.allgather(best) if self.comm.size > 1 else [best]
        value, *at = max(candidates, key=lambda b: (b[0],) + tuple(-c for c in b[1:]))
        value = max(value, 0.0)
        self._keep(value, t, at)
        return dict(zip(self.columns, [value] + at))

    def track(self, u, t):
        """The running maximum only, without communication (each rank keeps its own; summary()
        combines them): the per-step update between history rows."""
        if self.present:
            pen = self._penetration(u)
            if pen.size and pen.max() > self.worst["max_penetration"]:
                value, *at = self._best(pen)
                self._keep(value, t, at)

    def summary(self) -> dict:
        """The maximum over all steps so far (collective in parallel): the largest value, the
        earliest time among equal values, then the smallest coordinates."""
        if not self.present:
            return {}
        if self.comm.size == 1:
            return dict(self.worst)
        worst = [(w["max_penetration"], w["max_penetration_t"], *w["max_penetration_at"])
                 for w in self.comm.allgather(self.worst)]
        value, t, *at = max(worst, key=lambda b: (b[0], -b[1]) + tuple(-c for c in b[2:]
                                                                       if c == c))
        return {"max_penetration": value, "max_penetration_t": t, "max_penetration_at": at}

    def state(self) -> list:
        """[max, t, x...] (summary(); collective) for the checkpoint."""
        w = self.summary() or self.worst
        return [w["max_penetration"], w["max_penetration_t"], *w["max_penetration_at"]]

    def set_state(self, values):
        self.worst = {"max_penetration": float(values[0]), "max_penetration_t": float(values[1]),
                      "max_penetration_at": [float(v) for v in values[2:2 + self.d]]}


class ZetaProbe:
    """zeta at the vertex nearest to ``point`` (None: no probe) and the first time it reaches
    zeta_star (Example 2: the corner (0, 6))."""

    def __init__(self, Z, point):
        self.columns, self.point, self.comm = [], point, Z.mesh.comm
        self.first_zeta_star_time = None
        if point is None:
            return
        owned = Z.dofmap.index_map.size_local
        X = Z.tabulate_dof_coordinates()[:owned, :2]
        dist = np.linalg.norm(X - np.asarray(point, float), axis=1)
        local = float(dist.min()) if dist.size else np.inf
        best = self.comm.allreduce(local, op=MPI.MIN)
        owner = self.comm.allreduce(self.comm.rank if local <= best else self.comm.size, op=MPI.MIN)
        self.index = int(np.argmin(dist)) if self.comm.rank == owner else None
        self.location = self.comm.bcast(X[self.index].tolist() if self.index is not None else None,
                                        root=owner)
        self.columns = ["zeta_probe"]

    def __call__(self, zeta, t, zeta_star) -> dict:
        if self.point is None:
            return {}
        value = float(zeta.x.array[self.index]) if self.index is not None else 0.0
        value = self.comm.allreduce(value, op=MPI.SUM)
        if self.first_zeta_star_time is None and value <= zeta_star + 1e-12:
            self.first_zeta_star_time = t
        return {"zeta_probe": value}

    def summary(self) -> dict:
        if self.point is None:
            return {}
        return {"probe": self.location, "probe_zeta_star_time": self.first_zeta_star_time}


class DamageProfiles:
    """Nodal values of zeta on the horizontal grid line x_2 = ``x2`` (structured meshes: the
    vertices on the line), kept every ``every`` seconds of model time; None: off."""

    def __init__(self, Z, x2, every, k):
        self.x2, self.every, self.k, self.comm = x2, every, k, Z.mesh.comm
        self.times, self.values = [], []
        if x2 is None:
            return
        owned = Z.dofmap.index_map.size_local
        X = Z.tabulate_dof_coordinates()[:owned, :2]
        self.index = np.flatnonzero(np.abs(X[:, 1] - x2) <= 1e-10 * max(1.0, abs(x2)))
        x1 = np.concatenate(self.comm.allgather(X[self.index, 0]))
        self.order = np.argsort(x1, kind="stable")
        self.x1 = x1[self.order]
        if self.x1.size == 0:
            raise InputError(f"no mesh vertices on the profile line x2 = {x2}")

    def _values(self, zeta):
        return np.concatenate(self.comm.allgather(zeta.x.array[self.index]))[self.order]

    def sample(self, zeta, t):
        if self.x2 is None:
            return
        if abs(t / self.every - round(t / self.every)) * self.every < 0.5 * self.k:
            self.times.append(t)
            self.values.append(self._values(zeta).tolist())

    def summary(self, zeta, t) -> dict:
        if self.x2 is None:
            return {}
        return {"profiles": {"x2": self.x2, "x1": self.x1.tolist(), "times": list(self.times),
                             "zeta": list(self.values), "last_t": t,
                             "last_zeta": self._values(zeta).tolist()}}
