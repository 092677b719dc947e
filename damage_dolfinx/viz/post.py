"""Post-processing: coarse-to-fine transfer on nested structured meshes (errors against a
reference solution, in parallel) and matplotlib figures of fields on the deformed configuration.
"""
from __future__ import annotations

import numpy as np
import ufl
from mpi4py import MPI

from damage_dolfinx import compat
from damage_dolfinx.forms.constitutive import eps
from damage_dolfinx.viz.figstyle import styled


# ---------------------------------------------------------------------------- nested transfer
class NestedTransfer:
    """Exact transfer of a P1 field from a coarse structured mesh to a nested fine mesh.

    Both meshes are cut from grids of the same rectangle with diagonals 'right' (the square
    [i, i+1] x [j, j+1] is split along (i, j)-(i+1, j+1)); the coarse P1 interpolant is then
    linear on every fine cell, so evaluating it at the fine dofs is exact. Two halves:
    :meth:`grid_values` gathers the coarse nodal values into grid order on every rank of the
    coarse mesh (coarse meshes are small); :meth:`to_fine` evaluates the fine dofs from them by
    a sparse matrix of precomputed barycentric weights (no point search, any partition). The
    halves can live on different communicators: a coarse run on one rank sends its grid values
    to the ranks of the fine mesh (convergence.py). ``V_coarse`` (``V_fine``) may be None where
    only :meth:`to_fine` (:meth:`grid_values`) is used.
    """

    def __init__(self, V_coarse, V_fine, grid):
        import scipy.sparse
        self.grid = grid
        self.bs = (V_fine or V_coarse).dofmap.index_map_bs
        self.grid_shape = ((grid.nx + 1) * (grid.ny + 1), self.bs)
        hx, hy = grid.Lx / grid.nx, grid.Ly / grid.ny
        if V_coarse is not None:
            self.comm = V_coarse.mesh.comm
            n_owned = V_coarse.dofmap.index_map.size_local
            xc = V_coarse.tabulate_dof_coordinates()[:n_owned]
            i = np.rint((xc[:, 0] - grid.x0) / hx).astype(np.int64)
            j = np.rint((xc[:, 1] - grid.y0) / hy).astype(np.int64)
            self._coarse_owned = n_owned
            self._coarse_grid_index = j * (grid.nx + 1) + i
        if V_fine is None:
            return
        xf = V_fine.tabulate_dof_coordinates()
        s = (xf[:, 0] - grid.x0) / hx
        t = (xf[:, 1] - grid.y0) / hy
        ci = np.clip(np.floor(s + 1e-9), 0, grid.nx - 1)
        cj = np.clip(np.floor(t + 1e-9), 0, grid.ny - 1)
        s, t = np.clip(s - ci, 0.0, 1.0), np.clip(t - cj, 0.0, 1.0)
        ci, cj = ci.astype(np.int64), cj.astype(np.int64)
        node = lambda di, dj: (cj + dj) * (grid.nx + 1) + (ci + di)  # noqa: E731
        lower = s >= t  # triangle (0,0),(1,0),(1,1) of the cell
        nodes = np.stack([node(0, 0), np.where(lower, node(1, 0), node(0, 1)), node(1, 1)], 1)
        weights = np.stack([np.where(lower, 1 - s, 1 - t), np.where(lower, s - t, t - s),
                            np.where(lower, t, s)], 1)
        rows = np.repeat(np.arange(len(xf)), 3)
        self._P = scipy.sparse.csr_matrix((weights.ravel(), (rows, nodes.ravel())),
                                          shape=(len(xf), self.grid_shape[0]))

    def grid_values(self, u_coarse):
        """The coarse nodal values in grid order, (nodes, bs), on every rank of the coarse
        mesh; nodes in holes are 0 (they get weight 0)."""
        vals = u_coarse.x.array.reshape(-1, self.bs)[:self._coarse_owned]
        idx_all = self.comm.allgather(self._coarse_grid_index)
        val_all = self.comm.allgather(vals)
        on_grid = np.zeros(self.grid_shape)
        on_grid[np.concatenate(idx_all)] = np.concatenate(val_all)
        return on_grid

    def to_fine(self, on_grid, u_fine):
        """u_fine <- the coarse field given by its grid values, at the fine dofs (all local)."""
        u_fine.x.array[:] = (self._P @ on_grid).reshape(-1)

    def __call__(self, u_coarse, u_fine):
        """u_fine <- coarse P1 field u_coarse evaluated at the fine dofs (all local dofs)."""
        self.to_fine(self.grid_values(u_coarse), u_fine)


class NestedTransferDG0:
    """Exact transfer of a piecewise-constant field (any block size, e.g. the DG0 stress
    tensors of Section 2.4) from a coarse structured mesh to a nested fine mesh: every fine
    cell lies in one coarse cell, found from its centroid in the common grid (same layout and
    same two halves as :class:`NestedTransfer`: square (i, j), lower triangle when s >= t)."""

    def __init__(self, V_coarse, V_fine, grid):
        self.grid = grid
        self.bs = (V_fine or V_coarse).dofmap.index_map_bs
        self.grid_shape = (2 * grid.nx * grid.ny, self.bs)
        if V_coarse is not None:
            self.comm = V_coarse.mesh.comm
            nc = compat.num_owned_cells(V_coarse.mesh)
            self._coarse_dofs = compat.cell_dofs(V_coarse)[:, 0]
            self._coarse_index = self._grid_cell(compat.cell_midpoints(V_coarse.mesh)[:nc])
        if V_fine is None:
            return
        fine_cells = compat.cell_midpoints(V_fine.mesh)
        self._fine_index = self._grid_cell(fine_cells)
        dl = V_fine.dofmap.list
        arr = dl.array.reshape(-1, dl.links(0).size) if hasattr(dl, "array") else dl
        self._fine_dofs = arr[:len(fine_cells), 0]

    def _grid_cell(self, x):
        g = self.grid
        s, t = (x[:, 0] - g.x0) / (g.Lx / g.nx), (x[:, 1] - g.y0) / (g.Ly / g.ny)
        i = np.clip(np.floor(s), 0, g.nx - 1).astype(np.int64)
        j = np.clip(np.floor(t), 0, g.ny - 1).astype(np.int64)
        upper = (t - j) > (s - i)
        return 2 * (j * g.nx + i) + upper

    def grid_values(self, u_coarse):
        vals = u_coarse.x.array.reshape(-1, self.bs)[self._coarse_dofs]
        idx_all = self.comm.allgather(self._coarse_index)
        val_all = self.comm.allgather(vals)
        on_grid = np.zeros(self.grid_shape)
        on_grid[np.concatenate(idx_all)] = np.concatenate(val_all)
        return on_grid

    def to_fine(self, on_grid, u_fine):
        fine = u_fine.x.array.reshape(-1, self.bs)
        fine[self._fine_dofs] = on_grid[self._fine_index]

    def __call__(self, u_coarse, u_fine):
        self.to_fine(self.grid_values(u_coarse), u_fine)


def nested_transfer(V_coarse, V_fine, grid):
    """The exact nested transfer for P1 (:class:`NestedTransfer`) or DG0 fields (either space
    may be None where only one half is used: see :class:`NestedTransfer`)."""
    degree = compat.element_degree(V_fine or V_coarse)
    return NestedTransferDG0(V_coarse, V_fine, grid) if degree == 0 else \
        NestedTransfer(V_coarse, V_fine, grid)


#: the norms of an error component (``Model.error_components``): the V norm ||eps(.)||_L2, the
#: L2 norm, the L2 norm on Gamma_C (facet tag 3) of a field that lives there only
NORMS = ("V", "L2", "L2_GammaC")


class ComponentNorm:
    """||f_ref - f||_V (= ||eps(.)||_L2, displacements), ||f_ref - f||_L2 or, for a field on
    the contact boundary only (norm ``L2_GammaC``, with the reference mesh's ``facet_tags``),
    ||f_ref - f||_{L2(Gamma_C)} of one error component, with f given on the fine mesh:
    sqrt(e^T G e) with the Gram matrix G of the norm assembled once (the same quadrature as
    assembling the scalar form each time, whose value it equals to round-off, at a fraction of
    the cost: one sparse product per call)."""

    def __init__(self, f_ref, norm: str, facet_tags=None):
        from dolfinx import fem
        if norm not in NORMS:
            raise ValueError(f"unknown error norm {norm!r} ({', '.join(NORMS)})")
        if norm == "L2_GammaC" and facet_tags is None:
            raise ValueError("the norm L2_GammaC needs the mesh's facet tags")
        self.f_ref, self.e = f_ref, fem.Function(f_ref.function_space)
        V = f_ref.function_space
        du, w = ufl.TrialFunction(V), ufl.TestFunction(V)
        if norm == "V":
            a = ufl.inner(eps(du), eps(w)) * ufl.dx
        elif norm == "L2":
            a = ufl.inner(du, w) * ufl.dx
        else:
            from damage_dolfinx.core.tags import GAMMA_C
            a = ufl.inner(du, w) * ufl.ds(domain=V.mesh, subdomain_data=facet_tags,
                                          subdomain_id=GAMMA_C)
        a = compat.form(a)
        self.G = compat.create_matrix(a)
        compat.assemble_matrix(self.G, a, [])
        self.G.assemble()
        self._e_vec, self._y = compat.petsc_vec(self.e), self.G.createVecLeft()

    def __call__(self, f_fine) -> float:
        np.subtract(self.f_ref.x.array, f_fine.x.array, out=self.e.x.array)
        self.G.mult(self._e_vec, self._y)
        return float(np.sqrt(abs(self._e_vec.dot(self._y))))


# ---------------------------------------------------------------------------- figures
def diameter(msh) -> float:
    """The diagonal of the mesh's bounding box (over all ranks)."""
    from mpi4py import MPI
    x = msh.geometry.x
    lo = np.array(x.min(axis=0) if x.size else np.full(3, np.inf), dtype=float)
    hi = np.array(x.max(axis=0) if x.size else np.full(3, -np.inf), dtype=float)
    msh.comm.Allreduce(MPI.IN_PLACE, lo, op=MPI.MIN)
    msh.comm.Allreduce(MPI.IN_PLACE, hi, op=MPI.MAX)
    return float(np.linalg.norm(hi - lo))


def gather_cells(u_disp, field, amplification: float = 0.0):
    """On rank 0: deformed triangle coordinates (nc, 3, 2) and values of ``field`` (P1 -> (nc, 3),
    DG0 -> (nc,)) for all owned cells; None on other ranks."""
    msh = field.function_space.mesh
    xy = compat.cell_vertex_coords(msh).copy()
    if u_disp is not None and amplification:
        cd = compat.cell_dofs(u_disp.function_space)
        xy += amplification * u_disp.x.array.reshape(-1, 2)[cd]
    values = field.x.array[compat.cell_dofs(field.function_space)]
    values = values[:, 0] if values.shape[1] == 1 else values
    xy_all, val_all = msh.comm.gather(xy, root=0), msh.comm.gather(values, root=0)
    if msh.comm.rank != 0:
        return None
    return np.concatenate(xy_all), np.concatenate(val_all)


def plot_fields(u_disp, fields, path, amplification=1.0, title="", outline=None, mesh_lines=False,
                zeta_star=None):
    """One PNG of ``fields`` ((Function, label) pairs) on the configuration x + amplification * u
    (docs/models.md, "Output conventions"), drawn by figstyle (damage on [zeta*, 1], round
    factor in the title).
    ``mesh_lines``: a thesis "deformed mesh" figure -- the mesh edges on the deformed body over
    the undeformed outline, no colour field. The panel data are saved next to the PNG
    (``.npz``) so that thesis pairs can be re-rendered on a shared scale. Collective."""
    from damage_dolfinx.viz import figstyle
    amplification = figstyle.drawn_amplification(amplification)  # e.g. the automatic one
    if zeta_star is None:
        zeta_star = _run_zeta_star(path)
    gathered = [gather_cells(u_disp, f, amplification) for f, _ in fields]
    ref = gather_cells(None, fields[0][0], 0.0) if outline else None
    if MPI.COMM_WORLD.rank != 0 or gathered[0] is None:
        return
    panels = [{"xy": g[0], "values": g[1], "name": getattr(f, "name", ""), "label": label}
              for g, (f, label) in zip(gathered, fields)]
    meta = dict(title=title, amplification=amplification, zeta_star=zeta_star,
                mesh_only=bool(mesh_lines))
    figstyle.render_fields(panels, path, ref_xy=ref[0] if ref else None, **meta)
    figstyle.save_panels(path, panels, ref_xy=ref[0] if ref else None, **meta)


def _run_zeta_star(png_path):
    """zeta_star of the run that draws ``png_path``: its summary.json (written by the runner
    at step 0) lies in the same folder; None if there is none."""
    import json
    from pathlib import Path
    try:
        summary = json.loads((Path(png_path).parent / "summary.json").read_text())
        return float(summary["parameters"]["zeta_star"])
    except (OSError, ValueError, KeyError, TypeError):
        return None


@styled
def plot_mesh(geometry, path, title="", labels=None, loads=None, split=None):
    """The undeformed mesh with its tagged boundary parts (thesis 'setting' figures): Gamma_D
    with clamp hatching, Gamma_C with the foundation drawn under it, load arrows (``loads``
    from :func:`setting_loads`: traction on the Gamma_N facets, body force inside), the legend
    below the axes; collective."""
    from damage_dolfinx.viz import figstyle
    from damage_dolfinx.core.tags import GAMMA_N
    msh, tags = geometry.mesh, geometry.facet_tags
    xy = msh.comm.gather(compat.cell_vertex_coords(msh), root=0)
    parts = {}
    for tag in set(labels or {}) | {GAMMA_N}:
        local = compat.facet_vertex_coords(msh, tags.indices[tags.values == tag])
        parts[tag] = msh.comm.gather(local, root=0)
    if msh.comm.rank != 0:
        return
    cells = np.concatenate(xy)
    styles = ("tab:red", "tab:blue", "tab:green")
    drawn = [(np.concatenate(parts[tag]), colour, label, "clamp" in label or "contact" in label)
             for (tag, label), colour in zip((labels or {}).items(), styles)]
    arrows, notes = [], []
    for kind, expr, constants, t_const, times in (loads or []):
        diameter = max(np.ptp(cells.reshape(-1, 2), axis=0))
        if kind == "f_N":  # about one arrow per 10 % of the body's size along Gamma_N
            where = np.concatenate(parts[GAMMA_N])
            facet = float(np.median(np.linalg.norm(where[:, 1] - where[:, 0], axis=1)))
            where = where[figstyle.spread(where.mean(1), max(0.08 * diameter, 2 * facet))]
        else:
            where = figstyle.body_force_points(cells, 0.15 * diameter)
        points = where.mean(1) if kind == "f_N" else where
        try:
            t, vectors = _strongest_load(expr, constants, t_const, times, points)
        except Exception as exc:  # noqa: BLE001 -- a load UFL cannot evaluate pointwise
            notes.append(f"${kind}$ not drawn ({type(exc).__name__})")
            continue
        if t is None:
            continue
        peak = float(np.max(np.linalg.norm(vectors, axis=1)))
        name = "traction" if kind == "f_N" else "body force"
        when = "constant" if t == "constant" else f"at $t$ = {t:.3g}"
        arrows.append((kind, where, vectors, f"${kind}$ ({name}, {when}): max |${kind}$| = {peak:.3g}"))
    if GAMMA_N in (labels or {}) and not notes:  # what Gamma_N carries, now that it is known
        loaded = any(kind == "f_N" for kind, *_ in arrows)
        drawn = [(segs, colour, f"Gamma_N ({'loaded' if loaded else 'traction-free'})"
                  if label == labels[GAMMA_N] else label, hatched)
                 for segs, colour, label, hatched in drawn]
    fig, (ax,) = figstyle.new_figure(1, figstyle.data_aspect(cells), panel_width=5.0)
    figstyle.draw_setting(ax, cells, drawn, arrows, note="; ".join(notes), split=split)
    figstyle.save(fig, path, title=figstyle.mathtext(title))


def setting_loads(stepper, samples=40):
    """The stepper's loads for its setting figure: [(kind, UFL vector, its constants,
    time constant, sample times)] for f_B and f_N (:func:`plot_mesh` draws each at the sampled
    time where it is largest). Collective (a problem's ``loads()`` may assemble)."""
    from ufl.algorithms import extract_type
    T = stepper.data.time.T
    times = np.linspace(0.0, T, samples + 1)[1:]
    out = []
    for kind, expr in zip(("f_B", "f_N"), stepper.loads()):
        if expr is not None:
            constants = {c: np.asarray(c.value) for c in extract_type(expr, ufl.Constant)}
            out.append((kind, expr, constants, stepper.t_const, times))
    return out


def _pointwise(expr):
    """(x, mapping, i) -> float(expr[i](x, mapping)): UFL's own pointwise evaluation, with its
    expansion of derivatives done once instead of at each call (most of a call's time; the
    setting figure makes 40 sample times x a dozen points x 2 components of them). The first
    value is computed both ways; UFL's call is kept where they differ (another UFL's
    internals)."""
    def slow(x, mapping, i):
        return float(expr[i](x, mapping))
    try:
        from ufl.algorithms import expand_derivatives
        from ufl.utils.stacks import StackDict
        expanded = expand_derivatives(expr)
    except (ImportError, AttributeError):
        return slow

    def fast(x, mapping, i):
        return float(expanded.evaluate(x, mapping, (i,), StackDict()))
    chosen = []

    def component(x, mapping, i):
        if chosen:
            return chosen[0](x, mapping, i)
        value = slow(x, mapping, i)
        try:
            same = fast(x, mapping, i) == value
        except Exception:  # noqa: BLE001 - internals of another UFL version
            same = False
        chosen.append(fast if same else slow)
        return value
    return component


def _strongest_load(expr, constants, t_const, times, points):
    """(t, values (npts, 2)) of the UFL vector ``expr`` at ``points`` for the time of
    ``times`` where its largest value is largest (t = "constant" if that never changes);
    (None, None) if it vanishes throughout."""
    component = _pointwise(expr)

    def values(t, pts):
        mapping = {c: (float(t) if c is t_const else (v if v.shape else float(v)))
                   for c, v in constants.items()}
        return np.array([[component(tuple(p), mapping, i) for i in range(2)] for p in pts])

    probe = points[::max(1, len(points) // 12)]  # the time is chosen on a dozen points
    peaks = [float(np.max(np.linalg.norm(values(t, probe), axis=1))) if len(probe) else 0.0
             for t in times]
    if not peaks or max(peaks) == 0.0:
        return None, None
    # the end of the first stretch at the peak: a periodic load is drawn in its first half
    # period (3.1-ex2 pushes toward the obstacle at t = 0.25 and pulls at t = 0.75), a load held
    # on a plateau at the plateau's end (2.3-ex3: t = 0.5)
    at_peak = np.asarray(peaks) >= max(peaks) * (1 - 1e-9)
    i = int(np.argmax(at_peak))
    while i + 1 < len(at_peak) and at_peak[i + 1]:
        i += 1
    t = float(times[i])
    return ("constant" if max(peaks) - min(peaks) <= 1e-12 * max(peaks) else t), values(t, points)


def _draw_outline(ax, xy):
    """Boundary edges of the undeformed mesh (kept for benchmarks/studies/lshape_3_1.py)."""
    from damage_dolfinx.viz import figstyle
    figstyle.draw_outline(ax, xy)


def loglog_rate(x, y):
    """Least-squares slope of log y against log x (the observed convergence rate)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    ok = (x > 0) & (y > 0)
    if ok.sum() < 2:
        return float("nan")
    return float(np.polyfit(np.log(x[ok]), np.log(y[ok]), 1)[0])


@styled
def plot_history(csv_path, columns, path, title=""):
    """Time histories of history.csv columns, one axis each (rank 0 only)."""
    import csv
    from damage_dolfinx.viz import figstyle
    pyplot = figstyle.plt()
    with open(csv_path) as f:
        rows = list(csv.DictReader(f))
    t = np.array([float(r["t"]) for r in rows])
    fig, axes = pyplot.subplots(len(columns), 1, figsize=(6.0, 2.2 * len(columns) + 0.6),
                                sharex=True, squeeze=False)
    for ax, (column, label) in zip(axes[:, 0], columns):
        ax.plot(t, [float(r[column]) if r[column] else np.nan for r in rows], lw=1.2)
        label, scale = figstyle.si_unit(label, np.nanmax(np.abs(ax.get_ylim())))
        ax.set_ylabel(figstyle.mathtext(label))
        figstyle.plain_ticks(ax.yaxis, scale)  # every tick written out: no '1e-11' multiplier
        ax.grid(True, alpha=0.3)
        if "zeta" in column:
            ax.set_ylim(0, 1.05)
    axes[-1, 0].set_xlabel("$t$ [s]")
    figstyle.save(fig, path, title=figstyle.mathtext(title))


@styled
def plot_damage_profiles(prof, history_csv, zeta_star, path, title, probe_column="zeta_probe",
                         probe_label="zeta(0, 6)"):
    """Thesis Figures 3.17/3.18: zeta along a line at several times (``prof`` = the stepper's
    {"x1", "x2", "times", "zeta", "last_t", "last_zeta"}) and the probe history from
    history.csv with the zeta_star line (rank 0 only)."""
    import csv
    from damage_dolfinx.viz import figstyle
    pyplot = figstyle.plt()
    with open(history_csv) as f:
        rows = list(csv.DictReader(f))
    t = [float(r["t"]) for r in rows]
    z = [float(r[probe_column]) for r in rows]
    fig, (left, right) = pyplot.subplots(1, 2, figsize=(10, 3.8))
    cmap = pyplot.get_cmap("viridis")
    curves = list(zip(prof["times"], prof["zeta"])) + [(prof["last_t"], prof["last_zeta"])]
    for i, (ti, zi) in enumerate(curves):
        last = i == len(curves) - 1
        left.plot(prof["x1"], zi, ls="--" if last else "-", lw=1.2,
                  color="k" if last else cmap(i / max(1, len(curves) - 1)),
                  label=f"t = {ti:.3g}" + (" (last)" if last else ""))
    left.set_xlabel("$x_1$ [m]")
    left.set_ylabel(f"$\\zeta$ on $x_2$ = {prof['x2']:g}   (1 = sound)")
    left.set_ylim(0, 1.05)
    left.grid(True, alpha=0.3)
    left.legend(fontsize=7, ncol=2)
    right.plot(t, z, lw=1.0)
    right.axhline(zeta_star, color="r", lw=0.8, ls=":", label=f"$\\zeta^*$ = {zeta_star:g}")
    right.set_xlabel("$t$ [s]")
    right.set_ylabel(figstyle.mathtext(probe_label))
    right.set_ylim(0, 1.05)
    right.grid(True, alpha=0.3)
    right.legend(fontsize=8)
    figstyle.save(fig, path, title=figstyle.mathtext(title))
