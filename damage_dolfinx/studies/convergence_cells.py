"""The cells of a convergence study and how their errors are computed against the reference
(convergence.py runs them in lockstep).

A coarse cell (n, k) runs on all ranks of the study (large cells) or serially on one rank
(``_owners``: shared out by cost per time level); at each of its time levels its error
components are transferred to the reference mesh (exactly, ``post.nested_transfer``, when the
family is nested; by point evaluation, point_transfer.py, otherwise) and computed there,

    e(n, k) = max over common time levels of sum_c ||c_ref - c_hk||_c,

the norms ``||.||_c`` those of the stepper's ``error_components`` (one product with a Gram
matrix each).
"""
from __future__ import annotations

import time

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from damage_dolfinx.numerics.solvers import ConvergenceError
from damage_dolfinx.core.parameters import InputError
from damage_dolfinx.runtime.runner import solver_step
from damage_dolfinx.studies.point_transfer import (COMPARISON, NESTED_COMPARISON, OUTSIDE_TOLERANCE,
                                                   PointValues, ReferencePoints)
from damage_dolfinx.viz import post


class _CoarseRun:
    """One coarse (n, k) cell: its stepper (on the ranks that run it) and its error components
    transferred to the reference mesh.

    ``owner`` None: the cell runs on all ranks of the study (large cells). Otherwise it runs
    serially on rank ``owner`` (``stepper`` is None on the other ranks), which sends the grid
    values of its components to the ranks of the reference mesh at each measurement.
    """

    def __init__(self, n, k, ratio, owner, stepper):
        self.n, self.k, self.ratio, self.owner, self.stepper = n, k, ratio, owner, stepper
        self.err_parts, self.err, self.err_T, self.wall = {}, 0.0, 0.0, 0.0

    @property
    def mine(self) -> bool:
        return self.stepper is not None

    def connect(self, ref, grid, h, transfers, norms, comm, ref_rank=None, world=None,
                outbox=None):
        """Set up the measurement against ``ref`` (collective on ``comm``, the reference's).
        ``ref_rank``: the reference runs on that rank of ``world`` alone (``ref`` is None on
        the others, which only send their cells' values, without waiting: ``outbox`` holds
        the sends in flight, shared by the cells of a rank)."""
        self.h, self.comm, self.norms = h, comm, norms
        self.ref_rank, self.world, self.outbox = ref_rank, world, outbox
        self.components = []
        if ref is None:  # a rank without the reference: the coarse halves of its own cells
            self._send = [transfers.coarse(f.function_space, grid, i)
                          for i, (_, f, _) in enumerate(self.stepper.error_components)] \
                if self.mine else []
            return
        coarse = dict((name, f) for name, f, _ in self.stepper.error_components) \
            if self.mine else {}
        for i, (name, f_ref, _) in enumerate(ref.error_components):
            fine_side = transfers(grid, f_ref.function_space, i)
            f = coarse.get(name)
            coarse_side = transfers.coarse(f.function_space, grid, i) if f is not None else None
            self.components.append((name, fine_side, coarse_side, f,
                                    fem.Function(f_ref.function_space)))
        self.err_parts = {name: 0.0 for name, *_ in self.components}

    def advance(self, initial=False):
        start = time.perf_counter()
        solver_step(self.stepper.initialize if initial else self.stepper.advance,
                    f"cell n = {self.n}, k = {self.k:g}, step {self.stepper.n + 1}")
        self.wall += time.perf_counter() - start

    def measure(self):
        """Error at the current common time level; collective on the reference's ranks (with
        a reference on rank 0 alone, the owner sends its grid values there, point to point)."""
        if self.ref_rank is not None and self.world.rank != self.ref_rank:
            if self.mine:  # send each component (the reference's order: same example)
                for (_, f, _), coarse_side in zip(self.stepper.error_components, self._send):
                    values = np.ascontiguousarray(coarse_side.grid_values(f))
                    self.outbox.append((self.world.Isend(values, dest=self.ref_rank, tag=7),
                                        values))
                if len(self.outbox) > MAX_SENDS_IN_FLIGHT:  # bound the memory of a fast rank
                    half = len(self.outbox) // 2
                    MPI.Request.Waitall([req for req, _ in self.outbox[:half]])
                    del self.outbox[:half]
            return
        total = 0.0
        for name, fine_side, coarse_side, f, f_fine in self.components:
            if self.owner is None or self.mine:
                on_grid = coarse_side.grid_values(f)
                if self.owner is not None and self.ref_rank is None and self.comm.size > 1:
                    self.comm.Bcast(on_grid, root=self.owner)
            else:
                on_grid = np.empty(fine_side.grid_shape)
                if self.ref_rank is None:
                    self.comm.Bcast(on_grid, root=self.owner)
                else:
                    self.world.Recv(on_grid, source=self.owner, tag=7)
            fine_side.to_fine(on_grid, f_fine)
            e = self.norms[name](f_fine)
            self.err_parts[name] = max(self.err_parts[name], e)
            total += e
        self.err = max(self.err, total)
        self.err_T = total  # the last measurement is at t = T


#: sends of cell values a rank may have in flight to the reference's rank (then it waits for
#: the older half): the cells' ranks run ahead of the reference by up to this many messages
MAX_SENDS_IN_FLIGHT = 400

#: coarse cells with at most this many mesh cells per side run serially, shared out among
#: the ranks (a 2-rank step of a small mesh is slower than a serial one); larger cells, like
#: the reference, run on all ranks
SERIAL_CELL_MAX_N = 64


def _owners(ns, ks, T, size, serial_max_n=SERIAL_CELL_MAX_N, exclude=None) -> dict:
    """(n, k) -> rank that runs the cell serially, or None (all ranks). The serial cells of each
    k (they step at the same time levels) are shared out greedily by cost, steps x vertices,
    to the rank with the least work in that k, then in total: the ranks wait for each other at
    every reference step, so the balance must hold per time level, not only on the sum.
    ``exclude``: a rank that gets no cell (the one running the reference alone)."""
    owners, total = {}, np.zeros(size)
    ranks = [r for r in range(size) if r != exclude] or list(range(size))
    for k in ks:
        in_k = np.zeros(size)
        for n in sorted(ns, reverse=True):
            if size == 1 or n > serial_max_n:
                owners[(n, k)] = None
                continue
            rank = min(ranks, key=lambda r: (in_k[r], total[r]))
            cost = (T / k) * (n + 1) ** 2
            in_k[rank] += cost
            total[rank] += cost
            owners[(n, k)] = rank
    return owners


def _cell_geometry(runs, comm):
    """{(n, k): (grid, h)} of every cell on every rank (each rank knows its own cells')."""
    mine = {(r.n, r.k): (r.stepper.data.geometry.grid, r.stepper.data.geometry.h)
            for r in runs if r.mine and (r.owner is None and comm.rank == 0 or r.owner is not None)}
    out = {}
    for part in comm.allgather(mine):
        out.update(part)
    return out


def _box(msh):
    """(lo, hi) of the mesh's nodes over its ranks (collective on its communicator)."""
    x = msh.geometry.x
    lo = np.array(x.min(axis=0) if len(x) else np.full(3, np.inf), dtype=float)
    hi = np.array(x.max(axis=0) if len(x) else np.full(3, -np.inf), dtype=float)
    if msh.comm.size > 1:
        msh.comm.Allreduce(MPI.IN_PLACE, lo, op=MPI.MIN)
        msh.comm.Allreduce(MPI.IN_PLACE, hi, op=MPI.MAX)
    return lo, hi


def check_family(ref, ref_n, runs, comm):
    """A family's levels are what a convergence study needs (before any step): every level's
    mesh spans the reference's domain (its bounding box, within half a cell) and the meshes
    refine as n grows (h strictly smaller at a larger n, the reference finest). A family that
    ignores n, or builds another domain at some n, is refused: its errors and rates would mean
    nothing. Collective on ``comm``."""
    mine = {}
    for r in runs:  # the distributed cells collectively (same order on every rank)
        if r.stepper is not None and r.owner is None:
            box = _box(r.stepper.mesh)
            if comm.rank == 0:
                mine[r.n] = (r.stepper.data.geometry.h, *box)
        elif r.stepper is not None and r.owner == comm.rank:
            mine[r.n] = (r.stepper.data.geometry.h, *_box(r.stepper.mesh))
    ref_box = None
    if ref is not None and ref.mesh.comm.size > 1:
        ref_box = (ref.data.geometry.h, *_box(ref.mesh))
    elif ref is not None:
        ref_box = (ref.data.geometry.h, *_box(ref.mesh))
    levels = {}
    for part in comm.allgather(mine):
        levels.update(part)
    ref_box = comm.bcast(ref_box if comm.rank == 0 else None, root=0)
    if ref_box is None:
        return
    levels[ref_n] = ref_box
    ns = sorted(levels)
    for a, b in zip(ns, ns[1:]):
        if not levels[b][0] < levels[a][0] * (1 - 1e-9):
            raise InputError(f"the meshes of this family cannot be compared: they do not "
                             f"refine as n grows, h = "
                             f"{levels[a][0]:.6g} at n = {a} and h = {levels[b][0]:.6g} at "
                             f"n = {b} (a family (comm, n) -> mesh must be finer at a larger n)")
    h_ref, lo_ref, hi_ref = ref_box
    for n in ns:
        h, lo, hi = levels[n]
        if max(np.abs(lo - lo_ref).max(), np.abs(hi - hi_ref).max()) > 0.5 * h + 1e-12:
            raise InputError(f"the meshes of this family cannot be compared: they do not cover "
                             f"one domain, n = {n} spans "
                             f"{np.round(lo, 6).tolist()}-{np.round(hi, 6).tolist()}, the "
                             f"reference n = {ref_n} {np.round(lo_ref, 6).tolist()}-"
                             f"{np.round(hi_ref, 6).tolist()}")


class _Transfers:
    """The coarse-to-fine transfers of a study: exact nested transfer (post.nested_transfer)
    when every mesh of the family is a nested structured grid of the reference's, point
    evaluation (point_transfer.py) otherwise. Collective on the study's ranks."""

    def __init__(self, ref, ref_n, ns, geometry, comm):
        ref_grid = comm.bcast(ref.data.geometry.grid if comm.rank == 0 else None, root=0)
        grids = [grid for grid, _ in geometry.values()]
        self.nested = ref_grid is not None and all(
            g is not None and ref_grid.nx % g.nx == 0 and ref_grid.ny % g.ny == 0
            for g in grids)
        structured = ref_grid is not None and all(g is not None for g in grids)
        if structured and not self.nested:  # a structured family keeps today's nested path
            bad = next(n for n in ns if ref_n % n)
            raise InputError(f"coarse mesh n = {bad} is not nested in the reference "
                             f"n = {ref_n}")
        self.comparison = NESTED_COMPARISON if self.nested else COMPARISON
        self.points, self.fine, self.coarse_sides = None, {}, []
        if not self.nested:  # the reference's dof points, every component, on every rank
            parts = [ReferencePoints(f.function_space) for _, f, _ in ref.error_components] \
                if ref is not None else None
            if ref is not None:
                self.fine = {i: p for i, p in enumerate(parts)}
            self.points = comm.bcast([p.points for p in parts] if comm.rank == 0 else None,
                                     root=0)

    def __call__(self, grid, V_fine, i):
        """The fine half for component ``i`` (shared by the cells of one grid)."""
        if not self.nested:
            return self.fine[i]
        key = (grid.nx, grid.ny, id(V_fine))
        if key not in self.fine:
            self.fine[key] = post.nested_transfer(None, V_fine, grid)
        return self.fine[key]

    def coarse(self, V_coarse, grid, i):
        if self.nested:
            return post.nested_transfer(V_coarse, None, grid)
        side = PointValues(V_coarse, self.points[i])
        self.coarse_sides.append((V_coarse.mesh, side))
        return side

    def check_coverage(self, runs, comm):
        """Refuse a family whose coarse meshes leave reference points farther than
        OUTSIDE_TOLERANCE h outside (before any step)."""
        if self.nested:
            return
        worst = 0.0, None
        for run in runs:
            for msh, side in self.coarse_sides:
                if run.mine and msh is run.stepper.mesh and side.outside > worst[0]:
                    worst = side.outside / run.h, (run.n, side.outside, run.h)
        found = comm.allgather(worst)
        ratio, detail = max(found, key=lambda w: w[0])
        if ratio > OUTSIDE_TOLERANCE:
            n, distance, h = detail
            raise InputError(f"the meshes of this family cannot be compared: reference points lie "
                             f"{distance:.3g} outside the coarse mesh n = {n} (h = {h:.3g}); "
                             "its meshes must cover the same domain")


def _norm_statement(components) -> str:
    """The norm of the errors, in words."""
    words = {"V": "||eps(.)||_L2 (the V norm)", "L2": "the L2 norm",
             "L2_GammaC": "the L2 norm on Gamma_C"}
    return ", ".join(f"{name}: {words[norm]}" for name, _, norm in components)


def _check_states(ref, runs, comm, when):
    """Stop the study (ConvergenceError on every rank) when the reference or a cell holds a
    NaN/inf or a zeta outside [zeta*, 1] (guards.state_problem; one allreduce)."""
    from damage_dolfinx.runtime.guards import state_problem
    detail = None
    for name, stepper in [("the reference", ref)] + [
            (f"the cell n = {r.n}, k = {r.k:g}", r.stepper) for r in runs if r.mine]:
        if stepper is not None and detail is None:
            code, text = state_problem(stepper)
            detail = f"{name} at {when}: {text}" if code else None
    if comm.allreduce(1 if detail else 0, op=MPI.MAX):
        detail = next(d for d in comm.allgather(detail) if d)
        raise ConvergenceError(f"{detail}; the study is stopped (the model or its data gave "
                               "numbers that cannot be right)")


def _component_norms(ref):
    """{name: ComponentNorm} of the reference stepper's ``error_components``."""
    tags = getattr(getattr(getattr(ref, "data", None), "geometry", None), "facet_tags", None)
    return {name: post.ComponentNorm(f, norm, tags) for name, f, norm in ref.error_components}


def _error_definition(components) -> str:
    label = {"V": "||{0} - {0}_hk||_V", "L2": "||{0} - {0}_hk||_L2",
             "L2_GammaC": "||{0} - {0}_hk||_L2(Gamma_C)"}
    return "max_n (" + " + ".join(label[norm].format(name) for name, _, norm in components) + ")"
