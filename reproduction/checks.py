"""Measurements on a figure's own data and the graded verdict of each thesis figure.

A figure's data are the ``.panel.npz`` post.plot_fields saves beside it (undeformed and deformed
vertex coordinates, stress and damage per vertex) and its run's ``history.csv`` and
``summary.json``. Each check of reproduction.figures.THESIS_FIGURES tests the quantity the quoted
thesis sentence is about and quotes our number; :func:`evidence` gathers what the figure's
data show and :func:`judge` grades it by the rules of reproduction.classes (one rule per class).
"""
from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

from damage_dolfinx.viz.figstyle import NARROW_DAMAGE, load_panels

#: a damage field within 1e-3 of 1 everywhere has not developed (nothing to locate)
NO_DAMAGE = 1e-3
#: rank correlation above which two fields "coincide" / "correspond"
RANK_AGREE = 0.5
#: rank correlation above which two runs' fields have the same pattern
RANK_SAME = 0.8


def fields(npz) -> dict:
    """Undeformed vertex coordinates, displacements, stress and damage of one figure's data."""
    panels, meta, ref = load_panels(npz)
    out = {"meta": meta}
    for p in panels:
        xy = np.asarray(p["xy"]).reshape(-1, 2)
        base = np.asarray(ref).reshape(-1, 2) if ref is not None else xy
        vals = np.asarray(p["values"])
        vals = vals.reshape(-1) if vals.ndim == 2 else np.repeat(vals, 3)
        amp = meta.get("amplification") or 1.0
        out.setdefault("base", base)
        out.setdefault("disp", (xy - base) / amp)
        key = "zeta" if p.get("name") == "zeta" or "zeta" in p.get("label", "") else "stress"
        out.setdefault(key, vals)
        if key == "stress":
            out.setdefault("stress_name", "von Mises strain" if "strain" in p.get("label", "")
                           or "strain" in p.get("name", "") else "von Mises stress")
    return out


def rank_correlation(a, b) -> float:
    from scipy.stats import spearmanr
    a, b = np.asarray(a, float), np.asarray(b, float)
    if np.ptp(a) == 0 or np.ptp(b) == 0:
        return float("nan")
    return float(spearmanr(a, b).correlation)


def on_same_points(src: dict, dst: dict, key: str):
    """``src[key]`` at the vertices of ``dst`` (nearest undeformed vertex: two runs on one mesh,
    or two figures of one run)."""
    from scipy.spatial import cKDTree
    _, idx = cKDTree(src["base"]).query(dst["base"])
    return src[key][idx]


def _rel(base, i):
    lo, hi = base.min(0), base.max(0)
    return ((base[i] - lo) / np.where(hi > lo, hi - lo, 1)).tolist()


def _along_length(base):
    """Each vertex's position along the body's length, 0 to 1: its projection on the principal
    axis of the vertex cloud (the handle of a slanted wrench, the long side of a beam)."""
    centred = base - base.mean(0)
    axis = np.linalg.svd(centred, full_matrices=False)[2][0]
    s = centred @ axis
    return (s - s.min()) / max(np.ptp(s), 1e-300)


def quadrant(rel) -> str:
    x, y = rel
    return ("lower" if y < 1 / 3 else "upper" if y > 2 / 3 else "middle") + " " + \
        ("left" if x < 1 / 3 else "right" if x > 2 / 3 else "centre")


def measure(npz, related=()) -> dict:
    """Numbers the checks need, from one figure's data (and its related figures' data)."""
    f = fields(npz)
    base, meta = f["base"], f["meta"]
    m = {"amplification": meta.get("amplification"), "zeta_star": meta.get("zeta_star") or 0.01,
         "stress_name": f.get("stress_name", "von Mises stress")}
    d = np.linalg.norm(f["disp"], axis=1)
    dmax = float(d.max()) or 1.0
    rel = (base - base.min(0)) / np.where(np.ptp(base, 0) > 0, np.ptp(base, 0), 1)
    m.update(u_max=float(d.max()), size=float(np.hypot(*np.ptp(base, 0))),

             u_top=float(d[rel[:, 1] > 0.999].max(initial=0) / dmax),
             u_bottom=float(d[rel[:, 1] < 0.001].max(initial=0) / dmax))
    others = [fields(r) for r in related if r]
    stress = f.get("stress")
    if stress is None:
        stress = next((on_same_points(o, f, "stress") for o in others if "stress" in o), None)
    if "zeta" in f:
        z, zs = f["zeta"], m["zeta_star"]
        i = int(np.argmin(z))
        m.update(zeta_min=float(z.min()), zeta_max=float(z.max()), zeta_min_at=_rel(base, i),
                 zeta_min_xy=base[i].tolist(), area_near_star=float(np.mean(z < zs + 0.09)))
        band = rel.min(1) < 0.05  # within 5 % of the bottom or the left side
        m["damage_band_ratio"] = float((1 - z[band]).mean() / max((1 - z[~band]).mean(), 1e-300))
        if stress is not None:
            m["rank_stress_damage"] = rank_correlation(stress, -z)
    if stress is not None:
        i = int(np.argmax(stress))
        m.update(stress_max=float(stress.max()), stress_max_at=_rel(base, i),
                 stress_max_along=float(_along_length(base)[i]))
        band = rel.min(1) < 0.05
        m["stress_band_ratio"] = float(stress[band].mean() / max(stress[~band].mean(), 1e-300))
    for o in others:  # a pair of runs on one mesh (Figures 2.4 and 2.5)
        if "zeta" in o and "zeta" in f:
            z_other = on_same_points(o, f, "zeta")
            m["pair_rank_zeta"] = rank_correlation(f["zeta"], z_other)
            m["pair_max_dzeta"] = float(np.abs(f["zeta"] - z_other).max())
        if "stress" in o and "stress" in f:
            m["pair_rank_stress"] = rank_correlation(f["stress"], on_same_points(o, f, "stress"))
    return m


def _between(m, c, key):
    return m[key] if key in m else c[key]


#: the least drawn deformation (amplified by the thesis's factor) a reader sees, as a share of
#: the body's size: a thesis that amplifies its deformation draws one at least this large
VISIBLE = 0.01

CHECKS = {  # name: (what is tested, predicate(measures, context) -> bool or None)
    "physical": ("the damage field plotted is within [ζ*, 1]",
                 lambda m, c: m["zeta_min"] >= m["zeta_star"] - 1e-6 and m["zeta_max"] <= 1 + 1e-6),
    "localised": ("damage concentrated (less than half of the body within 0.09 of ζ*)",
                  lambda m, c: m["area_near_star"] < 0.5),
    "min_zeta_lower_right": ("most damaged point in the lower right",
                             lambda m, c: quadrant(m["zeta_min_at"]) == "lower right"),
    "min_zeta_top_or_lower_right": ("most damaged point on the upper boundary or lower right",
                                    lambda m, c: m["zeta_min_at"][1] > 0.9
                                    or quadrant(m["zeta_min_at"]) == "lower right"),
    "min_zeta_left": ("most damaged point near the clamped side (x1 in the left third)",
                      lambda m, c: m["zeta_min_at"][0] < 1 / 3),
    "damage_at_top_or_bottom": ("most damaged point on a contact boundary (top or bottom)",
                                lambda m, c: min(m["zeta_min_at"][1], 1 - m["zeta_min_at"][1]) < 0.05),
    "contact_bands": ("stress and damage (1 - ζ) higher on average in the contact bands (within "
                      "5 % of the bottom or the left side) than in the rest of the body",
                      lambda m, c: m["stress_band_ratio"] > 1 and m["damage_band_ratio"] > 1),
    "colocated": (f"stress and damage (1 - ζ) rank together (rank correlation ≥ {RANK_AGREE})",
                  lambda m, c: m["rank_stress_damage"] >= RANK_AGREE),
    "stress_pattern_same": (f"the stresses have the other run's pattern (rank correlation ≥ "
                            f"{RANK_SAME})", lambda m, c: m["pair_rank_stress"] >= RANK_SAME),
    "damage_pattern_differs": (f"the damage pattern differs from the other run's (rank "
                               f"correlation below {RANK_SAME})",
                               lambda m, c: m["pair_rank_zeta"] < RANK_SAME),
    "top_fixed_bottom_moves": ("upper boundary moves < 10 % of the lower one",
                               lambda m, c: m["u_top"] < 0.1 * max(m["u_bottom"], 1e-30)),
    "bottom_fixed": ("contact boundary (bottom) moves < 5 % of the largest displacement",
                     lambda m, c: m["u_bottom"] < 0.05),
    "no_penetration": ("penetration into the obstacle below 1 % of the largest displacement "
                       "(rms over the contact boundary at the final time, or the largest over "
                       "the run where the run records that)",
                       lambda m, c: c["penetration_last"] <= 0.01 * m["u_max"]),
    "displaced": ("the body not back in its initial position at the final time (||u||_L2 above "
                  "10 % of its largest value)", lambda m, c: c["u_L2_last"] > 0.1 * c["u_L2_max"]),
    "position_recovers": ("the body returns toward its stress-free position: ||u||_L2 at the "
                          "final time below half its value at t = 0",
                          lambda m, c: c["u_L2_last"] < 0.5 * c["u_L2_first"]),
    "four_hinges": ("a four-hinge mechanism (mechanism hinges of the bridge summary)",
                    lambda m, c: c["hinges"] == 4),
    "probe_reaches_star": ("ζ(0, 6) reaches ζ* in finite time",
                           lambda m, c: c["probe_min"] <= c["zeta_star"] + 1e-3),
    "minimum_at_edges": ("last profile most damaged at an edge point (x1 = 0 or 6)",
                         lambda m, c: c["last_min_at_edge"]),
    "deformation_grows": ("larger deformation at the later time under the same forces",
                          lambda m, c: c["u_last"] > 1.01 * c["u_first"]),
    "damage_increases_strain": ("damaged run strains more than the undamaged one (> 1 %)",
                                lambda m, c: c["strain_damaged"] > 1.01 * c["strain_undamaged"]),
    "as_drawn": ("a deformation of the size the thesis draws: amplified by the thesis's factor, "
                 f"the largest displacement is visible (at least {100 * VISIBLE:g} % of the "
                 "body's size) and stays below the body's size",
                 lambda m, c: VISIBLE * m["size"] <= c["thesis_amplification"] * m["u_max"]
                 <= m["size"]),
    "stress_central": ("highest stress in the central region (the middle third of the body's "
                       "length, along its principal axis)",
                       lambda m, c: abs(m["stress_max_along"] - 0.5) <= 1 / 6),
}

#: what each check is about (reproduction.figures.SUBJECTS): a figure may use a check only
#: when its quoted statement is about every subject the check tests
SUBJECTS = {
    "physical": ("damage",), "localised": ("damage",), "min_zeta_lower_right": ("damage",),
    "min_zeta_top_or_lower_right": ("damage",), "min_zeta_left": ("damage",),
    "damage_at_top_or_bottom": ("damage",), "contact_bands": ("stress", "damage"),
    "colocated": ("stress", "damage"), "stress_pattern_same": ("stress",),
    "damage_pattern_differs": ("damage",), "top_fixed_bottom_moves": ("configuration",),
    "bottom_fixed": ("configuration",), "no_penetration": ("contact",),
    "displaced": ("configuration",), "position_recovers": ("configuration",),
    "four_hinges": ("number",), "probe_reaches_star": ("damage",),
    "minimum_at_edges": ("damage",), "deformation_grows": ("configuration",),
    "damage_increases_strain": ("configuration",), "as_drawn": ("configuration",),
    "stress_central": ("stress",),
}

#: checks that hold by construction (the solver refuses a damage outside [zeta*, 1]): they
#: can make a verdict differ, never carry one (reproduction.classes.Evidence.sanity)
SANITY = ("physical",)

#: a share of the nodes more than 0.09 above zeta* below which the damage has no pattern to
#: judge (the body is at zeta* nearly everywhere)
PATTERN_SHARE = 0.1


def _contact_premise(m, c):
    """(holds, reason): contact exists where penetration is judged (the contact length or area
    at the final time, or over the run where the penetration is the largest over the run)."""
    length = c.get("contact_judged")
    if length is None:
        return None, "no contact length recorded"
    when = "over the run" if c.get("penetration_over_run") else "at the final time"
    return length > 0, (f"no contact {when} (contact length {length:.3g}): no penetration "
                        f"without contact proves nothing")


def _pattern_premise(m, c):
    """(holds, reason): the damage is away from zeta* somewhere, so that it has a pattern."""
    if "area_near_star" not in m:
        return None, "no damage field"
    away = 1 - m["area_near_star"]
    return away >= PATTERN_SHARE, (f"{100 * m['area_near_star']:.0f} % of the nodes within 0.09 "
                                   f"of ζ* (fewer than {100 * PATTERN_SHARE:.0f} % away from "
                                   f"it): a pattern inside a fully damaged body proves nothing")


#: the premise each check rests on: where it fails, the check fails with its reason
PREMISES = {"no_penetration": _contact_premise,
            **{name: _pattern_premise for name in (
                "min_zeta_lower_right", "min_zeta_top_or_lower_right", "min_zeta_left",
                "damage_at_top_or_bottom", "contact_bands", "colocated",
                "damage_pattern_differs")}}


def pair_context(fig, npzs) -> dict:
    """Measures across the files of one figure (two times, or two runs)."""
    c = {}
    if len(npzs) == 2 and all(npzs):
        a, b = (measure(n) for n in npzs)
        if "damage_increases_strain" in fig.checks:
            c["strain_undamaged"], c["strain_damaged"] = a["stress_max"], b["stress_max"]
        if "deformation_grows" in fig.checks:
            c["u_first"], c["u_last"] = a["u_max"], b["u_max"]
    return c


def run_context(folder) -> dict:
    """Measures from a run folder: history (u_L2, penetration, the probe), the last damage
    profile (3.3-ex2), the reading and its departures, the run's final time."""
    c = {}
    folder = Path(folder) if folder else None
    if folder is None:
        return c
    try:
        summary = json.loads((folder / "summary.json").read_text())
        c["zeta_star"] = float(summary["parameters"]["zeta_star"])
        c["status"], c["t_final"] = summary.get("status"), summary.get("t_final")
        from reproduction.classes import record_departures
        c["departures"] = record_departures(summary)
        with open(folder / "history.csv") as f:
            rows = list(csv.DictReader(f))
        col = lambda name: [float(r[name]) for r in rows if r.get(name)]  # noqa: E731
        if col("u_L2"):
            u = col("u_L2")
            c.update(u_L2_first=u[0], u_L2_last=u[-1], u_L2_max=max(u))
        contact = col("contact_length") or col("contact_area")
        if col("penetration_rms"):
            c["penetration_last"] = col("penetration_rms")[-1]
            if contact:
                c["contact_judged"] = contact[-1]
        elif summary.get("max_penetration") is not None:  # largest over the run (the wrench)
            c["penetration_last"] = float(summary["max_penetration"])
            c["penetration_over_run"] = True
            if contact:
                c["contact_judged"] = max(contact)
        if col("zeta_probe"):
            c["probe_min"] = min(col("zeta_probe"))
        if rows:
            c["t_last"] = float(rows[-1]["t"])
        prof = summary.get("profiles")
        if prof:
            x1, last = np.asarray(prof["x1"], float), np.asarray(prof["last_zeta"], float)
            edge = np.isclose(x1, x1.min()) | np.isclose(x1, x1.max())
            c["last_min_at_edge"] = bool(last[edge].min() <= last.min() + 1e-9)
    except (OSError, ValueError, KeyError, TypeError):
        pass
    return c


#: our number behind each check (quoted in the verdict)
NUMBERS = {
    "physical": lambda m, c: f"ζ in [{m['zeta_min']:.3g}, {m['zeta_max']:.3g}]",
    "localised": lambda m, c: f"{100 * m['area_near_star']:.0f} % of the nodes within 0.09 of ζ*",
    "min_zeta_lower_right": lambda m, c: f"most damaged at the {quadrant(m['zeta_min_at'])} "
                                         f"(x = {m['zeta_min_xy'][0]:.2g}, {m['zeta_min_xy'][1]:.2g})",
    "min_zeta_top_or_lower_right": lambda m, c: NUMBERS["min_zeta_lower_right"](m, c),
    "min_zeta_left": lambda m, c: NUMBERS["min_zeta_lower_right"](m, c),
    "damage_at_top_or_bottom": lambda m, c: NUMBERS["min_zeta_lower_right"](m, c),
    "contact_bands": lambda m, c: f"bands against the rest: stress {m['stress_band_ratio']:.2f}x, "
                                  f"damage {m['damage_band_ratio']:.2f}x",
    "colocated": lambda m, c: f"rank correlation {m['rank_stress_damage']:.2f}",
    "stress_pattern_same": lambda m, c: f"rank correlation {m['pair_rank_stress']:.2f}",
    "damage_pattern_differs": lambda m, c: f"rank correlation {m['pair_rank_zeta']:.2f}",
    "top_fixed_bottom_moves": lambda m, c: f"top edge {m['u_top']:.2f}, bottom edge "
                                           f"{m['u_bottom']:.2f} of max |u|",
    "bottom_fixed": lambda m, c: f"bottom edge {m['u_bottom']:.2f} of max |u|",
    "no_penetration": lambda m, c: f"penetration {c['penetration_last']:.2g} m, max |u| "
                                   f"{m['u_max']:.3g} m",
    "displaced": lambda m, c: f"||u||_L2 {c['u_L2_last']:.3g} m at the end, largest "
                              f"{c['u_L2_max']:.3g} m",
    "position_recovers": lambda m, c: f"||u||_L2 {c['u_L2_first']:.3g} m at t = 0, "
                                      f"{c['u_L2_last']:.3g} m at the end",
    "four_hinges": lambda m, c: f"{c['hinges']} mechanism hinges",
    "as_drawn": lambda m, c: f"max |u| {m['u_max']:.3g} m on a body of size {m['size']:.3g} m: "
                             f"x{c['thesis_amplification']:g} (the thesis's factor) gives "
                             f"{c['thesis_amplification'] * m['u_max'] / m['size']:.2g} times "
                             f"its size",
    "stress_central": lambda m, c: f"highest stress "
                                   f"{100 * abs(m['stress_max_along'] - 0.5):.0f} % of the "
                                   f"body's length from its middle",
    "probe_reaches_star": lambda m, c: f"min ζ(0, 6) = {c['probe_min']:.3g}",
    "minimum_at_edges": lambda m, c: "at an edge" if c["last_min_at_edge"] else "not at an edge",
    "deformation_grows": lambda m, c: f"max |u| {c['u_first']:.4g} m, then {c['u_last']:.4g} m "
                                      f"({100 * (c['u_last'] / c['u_first'] - 1):+.1f} %)",
    "damage_increases_strain": lambda m, c: f"max von Mises strain {c['strain_undamaged']:.4g} "
                                            f"undamaged, {c['strain_damaged']:.4g} damaged "
                                            f"({100 * (c['strain_damaged'] / c['strain_undamaged'] - 1):+.1f} %)",
}


def stopped_early(fig, c) -> str:
    """How a run stops before the time the thesis's statement is about ('' if it does not):
    a final time cut below the thesis's (quick runs), or a stop before it that is not the event
    the statement is about (the arch's collapse, ζ reaching ζ*)."""
    T = c.get("T_full")
    if not T:
        return ""
    if c.get("T_run") is not None and c["T_run"] < 0.999 * T:
        return f"the run stops at t = {c['T_run']:g} of the thesis's T = {T:g}"
    status, t_end = c.get("status"), c.get("t_final")
    if status and status != "completed" and status != fig.event and t_end is not None \
            and t_end < 0.999 * T:
        return f"the run stops at t = {t_end:.4g} of the thesis's T = {T:g} ({status})"
    return ""


def evidence(fig, npzs, related=(), context=None):
    """(Evidence of one field figure, what we get): the checks of the quoted statement measured
    on the figure's data, the departures of its run, an early stop, what the figure cannot show."""
    from reproduction.classes import ONE_COLOUR, Evidence
    from reproduction.figures import validate
    validate(fig)
    c = dict(context or {}, **pair_context(fig, npzs))
    if fig.thesis_amplification:
        c["thesis_amplification"] = fig.thesis_amplification
    first = next((n for n in npzs if n), None)
    m = measure(first, related) if first else {}
    checks, sanity = [], []
    for name in fig.checks:
        desc, pred = CHECKS[name]
        try:
            ok = bool(pred(m, c))
            number = NUMBERS[name](m, c) if name in NUMBERS else ""
        except (KeyError, TypeError, IndexError, ValueError, ZeroDivisionError):
            ok, number = None, ""
        if ok is not None and name in PREMISES:  # a check counts only when its premise holds
            holds, reason = PREMISES[name](m, c)
            if holds is None:
                ok, number = None, ""
            elif not holds:
                ok, number = False, f"{number}; premise fails: {reason}" if number else \
                    f"premise fails: {reason}"
        (sanity if name in SANITY else checks).append((desc, ok, number))
    zs = m.get("zeta_star", 0.01)
    if fig.about_damage and "zeta_min" in m and 1 - m["zeta_min"] < NO_DAMAGE:
        checks.append(("damage developed (ζ below 1 - 1e-3 somewhere)", False,
                       f"ζ ≥ {m['zeta_min']:.5g} everywhere"))
    invisible = ""
    if "pair_max_dzeta" in m and "damage_pattern_differs" in fig.checks \
            and m["pair_max_dzeta"] < ONE_COLOUR * (1 - zs):
        invisible = (f"the two damage fields differ by at most |Δζ| = {m['pair_max_dzeta']:.2g}"
                     f" on the fixed [{zs:g}, 1] scale (the same colours)")
    elif fig.about_damage and "zeta_min" in m and \
            m["zeta_max"] - m["zeta_min"] < ONE_COLOUR * (1 - zs):
        invisible = (f"on the fixed [{zs:g}, 1] scale the damage (ζ in [{m['zeta_min']:.3g}, "
                     f"{m['zeta_max']:.3g}]) is one colour")
    got = describe(m, c, fig.checks)
    e = Evidence(kind="result", statement=bool(fig.checks), no_statement=fig.no_statement,
                 quote=fig.quote,
                 checks=checks, sanity=sanity, departures=list(c.get("departures") or []),
                 stopped_early=stopped_early(fig, c), invisible=invisible,
                 quick=bool(c.get("quick")))
    if first is None and not c:
        e.checks, e.sanity = [], []
    return e, got or "-"


def judge(fig, npzs, related=(), context=None) -> tuple:
    """(verdict, what we get, failed checks) of one field figure; the verdict starts with its
    class (reproduction.classes.CLASSES)."""
    from reproduction.classes import classify
    e, got = evidence(fig, npzs, related, context)
    return classify(e), got, [c[0] for c in e.sanity + e.checks if c[1] is False]


def describe(m: dict, c: dict, checks=()) -> str:
    """What we get, in numbers (the summary's 'what we get' column)."""
    parts = []
    if "zeta_min" in m:
        parts.append(f"ζ in [{m['zeta_min']:.3g}, {m['zeta_max']:.3g}]")
        if 1 - m["zeta_min"] >= NO_DAMAGE:
            parts.append(f"most damaged at {quadrant(m['zeta_min_at'])} (x = "
                         f"{m['zeta_min_xy'][0]:.2g}, {m['zeta_min_xy'][1]:.2g}), "
                         f"{100 * m['area_near_star']:.0f} % of the nodes within 0.09 of ζ*")
    if "stress_max_at" in m:
        unit = "" if "strain" in m["stress_name"] else " Pa"
        parts.append(f"max {m['stress_name']} {m['stress_max']:.3g}{unit} at "
                     f"{quadrant(m['stress_max_at'])}")
    if "rank_stress_damage" in m and {"colocated", "contact_bands"} & set(checks):
        parts.append(f"rank correlation stress / damage {m['rank_stress_damage']:.2f}")
    if "contact_bands" in checks and "damage_band_ratio" in m:
        parts.append(f"contact bands against the rest: stress {m.get('stress_band_ratio', 0):.2f}x, "
                     f"damage {m['damage_band_ratio']:.2f}x")
    if "pair_rank_zeta" in m:
        parts.append(f"against Figure 2.4: stress rank correlation {m.get('pair_rank_stress', 0):.2f}, "
                     f"damage rank correlation {m['pair_rank_zeta']:.2f}, max |Δζ| "
                     f"{m['pair_max_dzeta']:.2g}")
    if "u_max" in m and {"top_fixed_bottom_moves", "bottom_fixed", "deformation_grows",
                         "no_penetration"} & set(checks):
        parts.append(f"max |u| = {m['u_max']:.3g} m on a body of size {m['size']:.3g} m (top "
                     f"edge {m['u_top']:.2f}, bottom edge {m['u_bottom']:.2f} of max |u|)")
    if {"position_recovers", "displaced"} & set(checks) and "u_L2_first" in c:
        parts.append(f"||u||_L2 {c['u_L2_first']:.3g} m at t = 0, largest {c['u_L2_max']:.3g} m, "
                     f"{c['u_L2_last']:.3g} m at the final time")
    if "no_penetration" in checks and "penetration_last" in c:
        parts.append(f"penetration {c['penetration_last']:.2g} m (rms at the final time, or the largest over the run)")
    for key, label in (("hinges", "mechanism hinges"), ("failure_load_kN", "failure load [kN]"),
                       ("probe_min", "min ζ(0, 6)"), ("u_first", "max |u| first"),
                       ("u_last", "max |u| later"), ("strain_undamaged", "max strain undamaged"),
                       ("strain_damaged", "max strain damaged")):
        if key in c:
            parts.append(f"{label} = {c[key]:.4g}")
    if "last_min_at_edge" in c:
        parts.append(f"last profile most damaged at an edge: {'yes' if c['last_min_at_edge'] else 'no'}")
    return "; ".join(parts)
