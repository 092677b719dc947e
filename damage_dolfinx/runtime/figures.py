"""The figures of a run (PNG): fields on the deformed shape, the mesh and its setting, histories,
damage profiles, 3-D sections."""
from __future__ import annotations

from pathlib import Path

import numpy as np
from mpi4py import MPI

from damage_dolfinx.core.tags import GAMMA_C, GAMMA_D, GAMMA_N
from damage_dolfinx.viz import post


def auto_amplification(stepper, diameter) -> float:
    """The factor that makes the largest displacement 10% of the domain diameter (where the
    thesis gives none)."""
    u = stepper.u.x.array.reshape(-1, 2)
    umax = stepper.comm.allreduce(float(np.max(np.linalg.norm(u, axis=1))) if u.size else 0.0,
                                  op=MPI.MAX)
    return 0.1 * diameter / umax if umax > 0 else 1.0


def _setting_split(ex, stepper):
    """Contact parts whose friction bound changes along them (3.2 Example 2: g = 1 on the top
    plane, 1000 on the bottom one): {label: (name, function of points)} for the setting figure."""
    builder = (getattr(ex, "builders", None) or {}).get("friction_bound")
    if builder is None:
        return None
    import ufl
    expr = builder(ufl.SpatialCoordinate(stepper.mesh))

    def values(points):
        return [float(expr(tuple(p))) for p in points]
    return {"Gamma_C (contact)": ("friction bound g", values)}


def draw_figure(ex, fig, stepper, out: Path, suffix="") -> dict:
    """One catalogue figure (PNG) of the current state; returns its file entry."""
    out = Path(out)
    if stepper.comm.rank == 0:
        out.mkdir(parents=True, exist_ok=True)
    stepper.comm.barrier()
    filename = fig.filename.replace(".png", f"{suffix}.png")
    if fig.kind == "history":  # history.csv is complete and flushed at the end of the run
        if stepper.comm.rank == 0:
            post.plot_history(out / "history.csv", fig.fields, out / filename, title=fig.title)
        return {"file": filename}
    if fig.kind == "profiles":  # damage along a line at several times + probe history
        if stepper.comm.rank == 0:
            post.plot_damage_profiles(stepper.summary_extra()["profiles"], out / "history.csv",
                                      stepper.params.zeta_star, out / filename, fig.title)
        return {"file": filename}
    if fig.kind == "problem":  # drawn by the stepper (collective): the vault's hinge lines
        stepper.draw_figure(fig, out / filename)
        return {"file": filename}
    if fig.kind == "slices" or stepper.mesh.topology.dim == 3:  # 3-D runs: fields on plane sections (slices.py)
        from damage_dolfinx.viz.slices import plot_slices
        planes = plot_slices([(stepper.von_mises, "von Mises stress [Pa]"),
                              (stepper.zeta, "damage zeta [-]")], out / filename,
                             title=f"{fig.title} (t = {stepper.t:.4g})",
                             zeta_star=stepper.params.zeta_star)
        return {"file": filename, "t": stepper.t, "sections": [list(p) for p in planes]}
    if fig.kind == "mesh":
        post.plot_mesh(stepper.data.geometry, out / filename, title=fig.title,
                       labels={GAMMA_D: "Gamma_D (clamped)", GAMMA_N: "Gamma_N (loaded/free)",
                               GAMMA_C: "Gamma_C (contact)"},
                       loads=post.setting_loads(stepper), split=_setting_split(ex, stepper))
        return {"file": filename}
    fields = {"von_mises": (stepper.von_mises, "von Mises stress [Pa]"),
              "zeta": (stepper.zeta, "damage zeta [-]")}
    fields.update(getattr(stepper, "figure_fields", {}))  # problem-specific (name: (Function, label))
    diameter = ex.diameter if ex.diameter == ex.diameter else post.diameter(stepper.mesh)
    amp = fig.amplification or auto_amplification(stepper, diameter)
    post.plot_fields(stepper.u, [fields[f] for f in fig.fields], out / filename,
                     amplification=amp, title=f"{fig.title} (t = {stepper.t:.4g})", outline=True,
                     mesh_lines=fig.mesh_lines)  # figstyle.readable keeps the drawing readable
    return {"file": filename, "t": stepper.t, "amplification": amp}
