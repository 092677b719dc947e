"""What each thesis figure shows (from the thesis text, with thesis.txt line numbers) and the
checks that compare our figure with it, measured on the figure's own data (the ``.npz`` panel
data that post.plot_fields saves next to every field figure).

Verdicts: *reproduced* when every check passes, *differs* (with the failed checks) otherwise,
*not comparable* when the figure has no check we can measure (histories, wire meshes of gmsh
geometries the thesis only sketches) or no output exists. Setting figures are *reproduced* when
the geometry and boundary parts are those stated in the text (the bridge's are assumed, G3).
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np


@dataclass
class ThesisFigure:
    number: str                 # "2.12"
    example: str                # catalogue id
    lines: str                  # thesis.txt lines of the caption and the description
    shows: str                  # what the thesis shows (paraphrase, quotes in '')
    files: tuple = ()           # our PNG names (in the figures folder), thesis order
    checks: tuple = ()          # names of checks in CHECKS, applied to the first field npz
    kind: str = "field"         # field | setting | convergence | history | assumed-setting

    @property
    def anchor(self) -> str:
        return "fig-" + self.number.replace(".", "-")


def _f(number, example, lines, shows, files, checks=(), kind="field"):
    return ThesisFigure(number, example, lines, shows, tuple(files), tuple(checks), kind)


THESIS_FIGURES = [
    _f("2.1", "2.1-ex1", "1060", "square (0,5)^2 with a clamped hole, mesh for n = 10",
       ["figure_2_1.png"], kind="setting"),
    _f("2.2", "2.1-ex1", "1083", "error against h + k: linear convergence (Table 2.1, withheld)",
       ["figure_2_2.png"], kind="convergence"),
    _f("2.3", "2.1-ex2a", "1086-1093", "disc |x| < 4 minus a diamond, mesh",
       ["figure_2_3.png"], kind="setting"),
    _f("2.4", "2.1-ex2a", "1093-1095", "von Mises stress and damage at t = 1 on the deformed "
       "body, tension damage only", ["figure_2_4.png"], ("physical", "localised")),
    _f("2.5", "2.1-ex2b", "1098-1100", "the same for compression damage only",
       ["figure_2_5.png"], ("physical", "localised")),
    _f("2.6", "2.1-ex3", "1119-1125", "masonry arch bridge geometry (sketch; dimensions not "
       "given, G3)", ["figure_2_6.png"], kind="assumed-setting"),
    _f("2.7", "2.1-ex3", "1130-1136", "force-displacement diagram; damage model fails at "
       "90 kN, 'ascending branch at failure' (our load rate is calibrated to the 90 kN, so the "
       "failure load is no independent check; the curve's shape is not measured)",
       ["figure_2_7.png"]),
    _f("2.8", "2.1-ex3", "1130-1141", "failure of the bridge: 'a four hinges mechanism'",
       ["figure_2_8.png"], ("four_hinges",)),
    _f("2.9", "2.1-ex3", "1130-1144", "damage at failure on the deformed body (x50), four hinges",
       ["figure_2_9.png"], ("physical", "four_hinges")),
    _f("2.10", "2.2-ex1", "1690-1701", "setting and mesh of the first example",
       ["figure_2_10.png"], kind="setting"),
    _f("2.11", "2.2-ex2", "1740-1747", "error against h + k (Table 2.4), linear convergence",
       ["figure_2_11.png"], kind="convergence"),
    _f("2.12", "2.2-ex3", "1753-1757", "deformed mesh (x3) at t = 5: 'the movement of the lower "
       "horizontal boundary, while the upper one remains clamped'; right: u_1 and sigma_tau at "
       "(4, 0), 'absence of movement until the friction bound is reached'",
       ["figure_2_12_left.png", "figure_2_12_right.png"], ("top_fixed_bottom_moves", "readable")),
    _f("2.13", "2.2-ex3", "1759-1762", "stress maximal on the upper boundary; 'the damage is "
       "concentrated on ... the contact boundaries'", ["figure_2_13.png"],
       ("physical", "localised", "damage_at_top_or_bottom")),
    _f("2.14", "2.3-ex1", "2169-2171", "unit square, mesh for n = 8", ["figure_2_14.png"],
       kind="setting"),
    _f("2.15", "2.3-ex1", "2193-2195", "error against h + k (Table 2.5), linear convergence",
       ["figure_2_15.png"], kind="convergence"),
    _f("2.16", "2.3-ex2", "2199-2202", "block pushed against a foundation", ["figure_2_16.png"],
       kind="setting"),
    _f("2.17", "2.3-ex2", "2207-2213", "von Mises at t = 0 and t = 2: 'at final time the body "
       "tends to recover the stress-free position'", ["figure_2_17_t0.png", "figure_2_17_t2.png"],
       ("stress_decreases",)),
    _f("2.18", "2.3-ex2", "2215-2218", "damage at the final time: 'the highest stressed areas "
       "coincide with the most damaged ones'", ["figure_2_18.png"], ("physical", "localised")),
    _f("2.19", "2.3-ex3", "2222-2227", "cantilever on a foundation", ["figure_2_19.png"],
       kind="setting"),
    _f("2.20", "2.3-ex3", "2239-2241", "von Mises at t = 0 and t = 0.5: same forces, larger "
       "deformation", ["figure_2_20_t0.png", "figure_2_20_t0.5.png"], ("deformation_grows",)),
    _f("2.21", "2.3-ex3", "2241-2246", "von Mises and damage at t = 1: load removed but 'the "
       "configuration is not the stress-free one'", ["figure_2_21.png"],
       ("physical", "stressed")),
    _f("2.22", "2.4-ex1", "2735-2741", "unit square, mesh for n = 8", ["figure_2_22_tresca.png"],
       kind="setting"),
    _f("2.23", "2.4-ex1", "2773", "errors against h + k, Tresca (left) and Coulomb (right)",
       ["figure_2_23_left.png", "figure_2_23_right.png"], kind="convergence"),
    _f("2.24", "2.4-ex1", "2765, 2782", "Tresca, t = 1, n = 64: 'due to the friction, the highest "
       "stressed area, and the corresponding most damaged one, is located at the right lower "
       "corner'", ["figure_2_24.png"], ("physical", "localised", "min_zeta_lower_right")),
    _f("2.25", "2.4-ex1", "2775, 2785", "Coulomb: most stressed/damaged 'at the upper boundary "
       "and at the right lower corner'", ["figure_2_25.png"],
       ("physical", "localised", "min_zeta_top_or_lower_right")),
    _f("2.26", "2.4-ex2", "2786-2788", "unit square without clamping, large friction bound",
       ["figure_2_26.png"], kind="setting"),
    _f("2.27", "2.4-ex2", "2797-2806", "deformed mesh at t = 1: 'the contact boundary remains "
       "clamped'", ["figure_2_27.png"], ("bottom_fixed", "readable")),
    _f("2.28", "2.4-ex2", "2804-2806", "most stressed and most damaged 'at the right lower "
       "contact corner'; right upper corner less damaged", ["figure_2_28.png"],
       ("physical", "localised", "min_zeta_lower_right")),
    _f("3.1", "3.1-ex1", "3318-3322", "unit square on a deformable foundation",
       ["figure_3_1.png"], kind="setting"),
    _f("3.2", "3.1-ex1", "3335-3352", "error against k + h (Table 3.1), linear convergence",
       ["figure_3_2.png"], kind="convergence"),
    _f("3.3", "3.1-ex2", "3339-3355", "beam clamped at x = 0 on a deformable foundation",
       ["figure_3_3.png"], kind="setting"),
    _f("3.4", "3.1-ex2", "3372-3376", "deformed mesh (x4) at t = 1 with the initial outline; no "
       "penetration into the obstacle", ["figure_3_4.png"], ("readable",)),
    _f("3.5", "3.1-ex2", "3376-3381", "highest stresses and most damaged areas 'near to the "
       "clamped part'", ["figure_3_5.png"], ("physical", "localised", "min_zeta_left")),
    _f("3.6", "3.1-ex3", "3383-3386", "L-shaped body on a deformable obstacle",
       ["figure_3_6_undamaged.png"], kind="setting"),
    _f("3.7", "3.1-ex3", "3401-3404", "deformed meshes (x10), undamaged and damaged: "
       "'inclusion of the damage effect leads to an increase of the magnitude of the deformation "
       "field' (the 'later time' of the check below is the damaged run)",
       ["figure_3_7_undamaged.png", "figure_3_7_damaged.png"], ("readable", "deformation_grows")),
    _f("3.8", "3.1-ex3", "3404-3407", "strains at the final time: 'inclusion of the damage "
       "effect leads to an increase of the magnitude of the deformation field'",
       ["figure_3_8_undamaged.png", "figure_3_8_damaged.png"], ("damage_increases_strain",)),
    _f("3.9", "3.2-ex1", "3954-3956", "unit square, bilateral contact, mesh for n = 8",
       ["figure_3_9.png"], kind="setting"),
    _f("3.10", "3.2-ex2", "3980-3982", "block between two frictional planes",
       ["figure_3_10.png"], kind="setting"),
    _f("3.11", "3.2-ex2", "3994-3998", "deformed mesh (x5): 'the lower part of the contact "
       "boundary remains fixed'", ["figure_3_11.png"], ("bottom_fixed", "readable")),
    _f("3.12", "3.2-ex2", "3995-4001", "'correspondence between the more stressed areas and the "
       "most damaged ones'", ["figure_3_12.png"], ("physical", "localised", "colocated")),
    _f("3.13", "3.2-ex3", "4005-4008", "block on a slope held by an obstacle (left), deformed "
       "configuration (right)", ["figure_3_13_left.png", "figure_3_13.png"]),
    _f("3.14", "3.2-ex3", "4021-4023", "'the contacting zones are the more stressed areas and "
       "therefore, the most damaged ones'", ["figure_3_14.png"],
       ("physical", "localised", "damage_at_bottom_or_left")),
    _f("3.15", "3.3-ex1", "4425-4431", "square (0,6)^2 setting", ["figure_3_15.png"],
       kind="setting"),
    _f("3.16", "3.3-ex1", "4452", "error against k + h (Table 3.3, withheld)",
       ["figure_3_16.png"], kind="convergence"),
    _f("3.17", "3.3-ex2", "4470-4476", "damage on x2 = 3 at several times (self-mending in the "
       "centre, minima at the edges) and zeta(0, 6) reaching ζ* in finite time",
       ["figure_3_17.png"], ("probe_reaches_star", "minimum_at_edges")),
    _f("3.18", "3.3-ex2", "4478-4485", "the same for the initial damage b, on x2 = 0",
       ["figure_3_18.png"], ("probe_reaches_star", "minimum_at_edges")),
    _f("3.19", "3.3-ex3", "4491-4494", "wrench on a stiff screw, cyclic traction",
       ["figure_3_19.png"], kind="assumed-setting"),
    _f("3.20", "3.3-ex3", "4506-4508", "deformed mesh (x2) at T; 'negligible amount of "
       "interpenetration'", ["figure_3_20.png"], ("readable",)),
    _f("3.21", "3.3-ex3", "4511-4513", "von Mises at T: highest 'at the central region where the "
       "wrench bends'", ["figure_3_21.png"]),
    _f("3.22", "3.3-ex3", "4515-4520", "damage at T: 'the highest damage coincides with the "
       "highest stress'", ["figure_3_22.png"], ("physical",)),
]


# ---------------------------------------------------------------------------- measurements
def _load(npz):
    from damage_dolfinx.viz.figstyle import load_panels
    return load_panels(npz)


def _nodes(panel, ref):
    """(undeformed vertex coordinates, displacement*amp, values) per vertex of the soup."""
    xy = np.asarray(panel["xy"]).reshape(-1, 2)
    base = np.asarray(ref).reshape(-1, 2) if ref is not None else xy
    vals = np.asarray(panel["values"])
    vals = vals.reshape(-1) if vals.ndim == 2 else np.repeat(vals, 3)
    return base, xy - base, vals


def measure(npz) -> dict:
    """Numbers a verdict needs, from one field figure's data (undeformed coordinates)."""
    panels, meta, ref = _load(npz)
    out = {"amplification": meta.get("amplification"), "zeta_star": meta.get("zeta_star")}
    for p in panels:
        base, disp, vals = _nodes(p, ref)
        lo, hi = base.min(0), base.max(0)
        rel = (base - lo) / np.where(hi > lo, hi - lo, 1)
        if p.get("name") == "zeta" or "zeta" in p.get("label", ""):
            zs = meta.get("zeta_star") or 0.01
            i = int(np.argmin(vals))
            out.update(zeta_min=float(vals.min()), zeta_max=float(vals.max()),
                       zeta_min_at=rel[i].tolist(), zeta_min_xy=base[i].tolist(),
                       area_near_star=float(np.mean(vals < zs + 0.09)))
        else:
            i = int(np.argmax(vals))
            out.setdefault("stress_max", float(vals.max()))
            out.setdefault("stress_max_at", rel[i].tolist())
        amp = meta.get("amplification") or 1.0
        d = np.linalg.norm(disp, axis=1) / amp
        dmax = float(d.max()) or 1.0
        out.update(u_max=float(d.max()), size=float(np.hypot(*(hi - lo))),
                   u_top=float(d[rel[:, 1] > 0.999].max(initial=0) / dmax),
                   u_bottom=float(d[rel[:, 1] < 0.001].max(initial=0) / dmax))
    return out


def _quadrant(rel) -> str:
    x, y = rel
    return ("lower" if y < 1 / 3 else "upper" if y > 2 / 3 else "middle") + " " + \
        ("left" if x < 1 / 3 else "right" if x > 2 / 3 else "centre")


CHECKS = {  # name: (description, predicate(measures, context) -> bool or None)
    "physical": ("zeta stays in [ζ*, 1]",
                 lambda m, c: m.get("zeta_min") is not None and m["zeta_min"] >= m["zeta_star"] - 1e-6
                 and m["zeta_max"] <= 1 + 1e-6),
    "localised": ("damage localised (less than half of the body within 0.09 of ζ*)",
                  lambda m, c: m.get("area_near_star") is not None and m["area_near_star"] < 0.5),
    "min_zeta_lower_right": ("most damaged point in the lower right",
                             lambda m, c: _quadrant(m["zeta_min_at"]) == "lower right"),
    "min_zeta_top_or_lower_right": ("most damaged point on the upper boundary or lower right",
                                    lambda m, c: m["zeta_min_at"][1] > 0.9
                                    or _quadrant(m["zeta_min_at"]) == "lower right"),
    "min_zeta_left": ("most damaged point near the clamped side (x1 in the left third)",
                      lambda m, c: m["zeta_min_at"][0] < 1 / 3),
    "damage_at_top_or_bottom": ("most damaged point on a contact boundary (top or bottom)",
                                lambda m, c: min(m["zeta_min_at"][1], 1 - m["zeta_min_at"][1]) < 0.05),
    "damage_at_bottom_or_left": ("most damaged point on a contact side (bottom or left)",
                                 lambda m, c: min(m["zeta_min_at"]) < 0.05),
    "colocated": ("most stressed and most damaged points within 20 % of the body size",
                  lambda m, c: np.hypot(*np.subtract(m["zeta_min_at"], m["stress_max_at"])) < 0.2),
    "top_fixed_bottom_moves": ("upper boundary moves < 10 % of the lower one",
                               lambda m, c: m["u_top"] < 0.1 * max(m["u_bottom"], 1e-30)),
    "bottom_fixed": ("contact boundary (bottom) moves < 5 % of the largest displacement",
                     lambda m, c: m["u_bottom"] < 0.05),
    "readable": ("the drawn (amplified) displacement stays below the body size, as in the "
                 "thesis's figure", lambda m, c: m["u_max"] * (m["amplification"] or 1) < m["size"]),
    "stressed": ("stress not zero at the final time", lambda m, c: m.get("stress_max", 0) > 0),
    "four_hinges": ("a four-hinge mechanism (mechanism hinges of the bridge summary)",
                    lambda m, c: c["hinges"] == 4 if c.get("hinges") is not None else None),
    "failure_load_90": ("failure load within 10 % of the thesis's 90 kN (the load rate is "
                        "calibrated to it at h = 0.05, k = 0.001)",
                        lambda m, c: abs(c["failure_load_kN"] / 90.0 - 1) <= 0.1
                        if "failure_load_kN" in c else None),
    "probe_reaches_star": ("zeta(0, 6) reaches ζ* in finite time",
                           lambda m, c: c["probe_min"] <= c["zeta_star"] + 1e-3
                           if "probe_min" in c else None),
    "minimum_at_edges": ("last profile most damaged at an edge point (x1 = 0 or 6)",
                         lambda m, c: c["last_min_at_edge"] if "last_min_at_edge" in c else None),
    "deformation_grows": ("larger deformation at the later time under the same forces",
                          lambda m, c: c["u_last"] > 1.01 * c["u_first"]
                          if "u_last" in c else None),
    "stress_decreases": ("max von Mises at the final time at least 10 % below t = 0",
                         lambda m, c: c["stress_last"] < 0.9 * c["stress_first"]
                         if "stress_last" in c else None),
    "damage_increases_strain": ("damaged run strains more than the undamaged one (> 1 %)",
                                lambda m, c: c["strain_damaged"] > 1.01 * c["strain_undamaged"]
                                if "strain_damaged" in c else None),
}


def _context(fig: ThesisFigure, npzs) -> dict:
    """Measures across the files of one figure (pairs in time / variants) and run summaries."""
    c = {}
    if fig.checks and "stress_decreases" in fig.checks and len(npzs) == 2 and all(npzs):
        c["stress_first"], c["stress_last"] = (measure(n)["stress_max"] for n in npzs)
    if "damage_increases_strain" in fig.checks and len(npzs) == 2 and all(npzs):
        c["strain_undamaged"], c["strain_damaged"] = (measure(n)["stress_max"] for n in npzs)
    if "deformation_grows" in fig.checks and len(npzs) == 2 and all(npzs):
        c["u_first"], c["u_last"] = (measure(n)["u_max"] for n in npzs)
    return c


def run_context(folder) -> dict:
    """Measures from a run folder (3.3-ex2: the probe history and the last damage profile)."""
    import csv
    import json
    c = {}
    folder = Path(folder) if folder else None
    if folder is None:
        return c
    try:
        summary = json.loads((folder / "summary.json").read_text())
        c["zeta_star"] = float(summary["parameters"]["zeta_star"])
        with open(folder / "history.csv") as f:
            probe = [float(r["zeta_probe"]) for r in csv.DictReader(f) if r.get("zeta_probe")]
        if probe:
            c["probe_min"] = min(probe)
        prof = summary.get("profiles")
        if prof:
            x1, last = np.asarray(prof["x1"], float), np.asarray(prof["last_zeta"], float)
            edge = np.isclose(x1, x1.min()) | np.isclose(x1, x1.max())
            c["last_min_at_edge"] = bool(last[edge].min() <= last.min() + 1e-9)
    except (OSError, ValueError, KeyError, TypeError):
        pass
    return c


def judge(fig: ThesisFigure, npzs, context=None) -> tuple:
    """(verdict, what we get, failed checks) for one thesis figure."""
    if fig.kind == "setting":
        return "reproduced", "the setting as stated in the text", []
    if fig.kind == "assumed-setting":
        return "not comparable", "geometry assumed (the thesis gives a sketch only)", []
    if not fig.checks:
        return "not comparable", describe({}, context or {}) or "no measurable statement", []
    first = next((n for n in npzs if n), None)
    c = dict(context or {}, **_context(fig, npzs))
    if first is None and not c:
        return "not comparable", "no figure data (.panel.npz) to measure", []
    m = measure(first) if first else {}
    results = []
    for name in fig.checks:
        desc, pred = CHECKS[name]
        try:
            ok = pred(m, c) if (m or name in CONTEXT_CHECKS) else None
        except (KeyError, TypeError, IndexError):
            ok = None
        results.append((name, desc, ok))
    got = describe(m, c, fig.checks)
    measured = [r for r in results if r[2] is not None]
    if not measured:
        return "not comparable", got or "no data", []
    failed = [desc for _, desc, ok in measured if not ok]
    return ("reproduced" if not failed else "differs"), got, failed


CONTEXT_CHECKS = {"four_hinges", "stress_decreases", "damage_increases_strain", "failure_load_90",
                  "probe_reaches_star", "minimum_at_edges", "deformation_grows"}
MOTION_CHECKS = {"top_fixed_bottom_moves", "bottom_fixed", "readable"}


def describe(m: dict, c: dict, checks=()) -> str:
    parts = []
    if "zeta_min" in m:
        parts.append(f"zeta in [{m['zeta_min']:.3g}, {m['zeta_max']:.3g}], most damaged at "
                     f"{_quadrant(m['zeta_min_at'])} (x = {m['zeta_min_xy'][0]:.2g}, "
                     f"{m['zeta_min_xy'][1]:.2g}), {100 * m['area_near_star']:.0f} % of the "
                     "nodes within 0.09 of ζ*")
    if "stress_max_at" in m:
        parts.append(f"max stress {m['stress_max']:.3g} at {_quadrant(m['stress_max_at'])}")
    if "u_max" in m and MOTION_CHECKS & set(checks):
        parts.append(f"max |u| = {m['u_max']:.3g} m on a body of size {m['size']:.3g} m, drawn "
                     f"x{m['amplification']:g} (top edge {m['u_top']:.2f}, bottom edge "
                     f"{m['u_bottom']:.2f} of max |u|)")
    for key in ("hinges", "failure_load_kN", "probe_min", "last_min_at_edge", "stress_first",
                "stress_last", "strain_undamaged", "strain_damaged", "u_first", "u_last"):
        if key in c:
            parts.append(f"{key.replace('_', ' ')} = {c[key]:.4g}" if not isinstance(c[key], bool)
                         else f"{key.replace('_', ' ')}: {'yes' if c[key] else 'no'}")
    return "; ".join(parts)


def figure_number(filename: str):
    """'figure_2_12_left.png' -> (2, 12, 'left'); None for other PNGs."""
    m = re.match(r"figure_(\d+)_(\d+)(?:_(.*))?\.png$", Path(filename).name)
    return (int(m.group(1)), int(m.group(2)), m.group(3) or "") if m else None
