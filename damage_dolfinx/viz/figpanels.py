"""Saved panel data of a field figure (``<png stem>.panel.npz``): a thesis pair re-rendered
on one stress scale after both runs finished, or a figure redrawn without its run."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .figscales import is_damage, shared_limits
from .figstyle import PANEL_SUFFIX, render_fields


def save_panels(path, panels, **meta):
    """The data behind a field figure (``<png stem>.panel.npz`` + JSON meta; not ``.npz``,
    which would overwrite a run's fields_final.npz behind fields_final.png), so that a thesis
    pair can be re-rendered on a shared stress scale after both runs finished
    (:func:`render_saved`)."""
    path = Path(path)
    arrays = {}
    for i, p in enumerate(panels):
        arrays[f"xy{i}"], arrays[f"v{i}"] = np.asarray(p["xy"]), np.asarray(p["values"])
    if meta.get("ref_xy") is not None:
        arrays["ref_xy"] = np.asarray(meta.pop("ref_xy"))
    else:
        meta.pop("ref_xy", None)
    meta["panels"] = [{"name": p.get("name", ""), "label": p.get("label", "")} for p in panels]
    arrays["meta"] = np.array(json.dumps(meta))
    np.savez_compressed(path.with_suffix(PANEL_SUFFIX), **arrays)


def load_panels(npz):
    d = np.load(npz)
    meta = json.loads(str(d["meta"]))
    panels = [dict(info, xy=d[f"xy{i}"], values=d[f"v{i}"])
              for i, info in enumerate(meta["panels"])]
    return panels, meta, (d["ref_xy"] if "ref_xy" in d else None)


def render_saved(npz, png, limits=None, guides=None) -> list:
    panels, meta, ref = load_panels(npz)
    return render_fields(panels, png, title=meta.get("title", ""),
                         amplification=meta.get("amplification", 1.0), ref_xy=ref,
                         zeta_star=meta.get("zeta_star"), mesh_only=meta.get("mesh_only", False),
                         limits=limits, guides=guides)


def render_pair(npz_a, npz_b, png_a, png_b):
    """Re-render two figures of a thesis pair with one stress scale per non-damage panel."""
    return render_shared([npz_a, npz_b], [png_a, png_b])


def render_shared(npzs, pngs):
    """Re-render figures of one run or one thesis pair with one scale per non-damage panel
    (a stress that has nearly vanished then reads as such, not as a stress field of its own)."""
    loaded = [load_panels(n)[0] for n in npzs]
    limits = {}
    for i in range(min(len(p) for p in loaded)):
        if not any(is_damage(p[i]["name"], p[i]["label"]) for p in loaded):
            limits[i] = shared_limits([p[i]["values"] for p in loaded])
    return [render_saved(n, png, limits) for n, png in zip(npzs, pngs)]
