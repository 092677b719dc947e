"""What each thesis figure shows, in the thesis's own words (the sentence a check tests is
quoted), and which checks compare our figure with it (reproduction/checks.py measures them on the
figure's own data, the ``.panel.npz`` that post.plot_fields saves next to every field figure).

Every check tests the quantity the quoted sentence is about: a position (the body returns to its
stress-free position), a trend (the deformation grows), a location (the most damaged area is at
the lower right corner) or a correspondence (stress and damage rank together). Where the thesis
only says what is plotted, the check is that our field is the one plotted (damage within
[zeta*, 1]).
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path


@dataclass
class ThesisFigure:
    number: str                 # "2.12"
    example: str                # catalogue id
    shows: str                  # what the thesis shows (paraphrase)
    files: tuple = ()           # our PNG names (in the figures folder), thesis order
    checks: tuple = ()          # names of checks in reproduction.checks.CHECKS
    kind: str = "field"         # field | setting | convergence | history | assumed-setting
    quote: str = ""             # the thesis sentence the checks test (verbatim)
    related: tuple = ()         # other figures whose data a check compares with (2.5 with 2.4)
    event: str = ""             # the run status that ends the thesis's run (collapse, ...)
    no_statement: str = ""      # why the thesis gives nothing to test (verdict: not comparable)
    thesis_run: str = ""        # the mesh and time step of the thesis's figure, where stated
    subject: tuple = ()         # what the quoted statement is about (SUBJECTS)
    thesis_amplification: float = 0.0  # the factor the thesis draws its deformation with

    @property
    def anchor(self) -> str:
        return "fig-" + self.number.replace(".", "-")

    @property
    def about_damage(self) -> bool:
        """True when the quoted statement is about the damage field (its visibility matters)."""
        return "damage" in self.subject


#: what a thesis statement can be about; each check of reproduction.checks.CHECKS tests one
#: or more of them (checks.SUBJECTS), and a figure may use only the checks of its statement's
#: subjects (:func:`validate`)
SUBJECTS = ("damage", "stress", "configuration", "contact", "number")


def _f(number, example, shows, files, checks=(), kind="field", quote="", related=(), event="",
       no_statement="", thesis_run="", subject=(), amplification=0.0):
    return ThesisFigure(number, example, shows, tuple(files), tuple(checks), kind, quote,
                        tuple(related), event, no_statement, thesis_run, tuple(subject),
                        amplification)


def validate(figure: ThesisFigure) -> ThesisFigure:
    """A figure's checks are those of its statement's subject; a quoted statement is tested.
    Raises ValueError otherwise (the report refuses such a figure)."""
    from reproduction.checks import CHECKS, SUBJECTS as CHECK_SUBJECTS
    if figure.kind != "field":
        return figure
    unknown = set(figure.subject) - set(SUBJECTS)
    if unknown:
        raise ValueError(f"Figure {figure.number}: unknown subject {sorted(unknown)}")
    if figure.quote and not figure.checks:
        raise ValueError(f"Figure {figure.number} quotes a statement but tests none of it: "
                         "give it the checks of its subject, or no quote")
    if figure.checks and not figure.subject:
        raise ValueError(f"Figure {figure.number}: its statement's subject is not tagged")
    for name in figure.checks:
        if name not in CHECKS:
            raise ValueError(f"Figure {figure.number}: no check {name!r}")
        outside = set(CHECK_SUBJECTS[name]) - set(figure.subject)
        if outside:
            raise ValueError(f"Figure {figure.number}: the check {name!r} tests "
                             f"{'/'.join(sorted(outside))}, which its statement (about "
                             f"{'/'.join(figure.subject)}) is not about")
    return figure


THESIS_FIGURES = [
    _f("2.1", "2.1-ex1", "square (0,5)^2 with a clamped hole, mesh for n = 10",
       ["figure_2_1.png"], kind="setting", thesis_run="n = 10"),
    _f("2.2", "2.1-ex1", "error against h + k: linear convergence (Table 2.1, not set beside ours)",
       ["figure_2_2.png"], kind="convergence"),
    _f("2.3", "2.1-ex2a", "disc |x| < 4 minus a diamond, mesh",
       ["figure_2_3.png"], kind="setting"),
    _f("2.4", "2.1-ex2a", "von Mises stress and damage at t = 1 on the deformed "
       "body, tension damage only", ["figure_2_4.png"],
       no_statement="the thesis's one sentence on Figure 2.4 says only what it plots (the von "
       "Mises stress and the damage at t = 1 on the deformed body); its one statement is the "
       "comparison with Figure 2.5, judged there"),
    _f("2.5", "2.1-ex2b", "the same for compression damage only; against Figure 2.4 the same stresses, a "
       "different damage distribution",
       ["figure_2_5.png"], ("physical", "stress_pattern_same", "damage_pattern_differs"),
       quote="If we compare Figures 2.4 and 2.5, we observe that there are no qualitative changes "
       "for the stresses, while important differences can be appreciated in the results "
       "concerning the damage distribution",
       related=["figure_2_4.png"], subject=("stress", "damage")),
    _f("2.6", "2.1-ex3", "masonry arch bridge geometry (sketch; dimensions not "
       "given)", ["figure_2_6.png"], kind="assumed-setting"),
    _f("2.7", "2.1-ex3", "force-displacement diagram; damage model fails at "
       "90 kN, 'ascending branch at failure' (our load rate is calibrated to the 90 kN, so the "
       "failure load is no independent check; the curve's shape is not measured)",
       ["figure_2_7.png"]),
    _f("2.8", "2.1-ex3", "failure of the bridge: 'a four hinges mechanism'",
       ["figure_2_8.png"], ("four_hinges",), event="collapse", thesis_run="h = 0.05, k = 0.001",
       quote="A four hinges mechanism arise in case of a quarter span load.", subject=("number",)),
    _f("2.9", "2.1-ex3", "damage at failure on the deformed body (x50), four hinges",
       ["figure_2_9.png"], ("four_hinges",), event="collapse",
       thesis_run="h = 0.05, k = 0.001",
       quote="A four hinges mechanism arise in case of a quarter span load.", subject=("number",),
       amplification=50),
    _f("2.10", "2.2-ex1", "setting and mesh of the first example",
       ["figure_2_10.png"], kind="setting"),
    _f("2.11", "2.2-ex2", "error against h + k (Table 2.4), linear convergence",
       ["figure_2_11.png"], kind="convergence"),
    _f("2.12", "2.2-ex3", "deformed mesh (x3) at t = 5: 'the movement of the lower "
       "horizontal boundary, while the upper one remains clamped'; right: u_1 and sigma_tau at "
       "(4, 0), 'absence of movement until the friction bound is reached'",
       ["figure_2_12_left.png", "figure_2_12_right.png"], ("top_fixed_bottom_moves", "as_drawn"),
       quote="We notice the movement of the lower horizontal boundary, while the upper one remains"
       " clamped", subject=("configuration",), amplification=3),
    _f("2.13", "2.2-ex3", "stress maximal on the upper boundary; 'the damage is "
       "concentrated on ... the contact boundaries'", ["figure_2_13.png"],
       ("physical", "localised", "damage_at_top_or_bottom"),
       quote="As we expected, the damage is concentrated on the most stressed areas, the contact "
       "boundaries.", subject=("damage",)),
    _f("2.14", "2.3-ex1", "unit square, mesh for n = 8", ["figure_2_14.png"],
       kind="setting", thesis_run="n = 8"),
    _f("2.15", "2.3-ex1", "error against h + k (Table 2.5), linear convergence",
       ["figure_2_15.png"], kind="convergence"),
    _f("2.16", "2.3-ex2", "block pushed against a foundation", ["figure_2_16.png"],
       kind="setting"),
    _f("2.17", "2.3-ex2", "von Mises at t = 0 and t = 2: 'at final time the body "
       "tends to recover the stress-free position'", ["figure_2_17_t0.png", "figure_2_17_t2.png"],
       ("position_recovers",),
       quote="Since a constant force was applied, the effect of the memory can be seen, because at"
       " final time the body tends to recover the stress-free position.",
       subject=("configuration",)),
    _f("2.18", "2.3-ex2", "damage at the final time: 'the highest stressed areas "
       "coincide with the most damaged ones'", ["figure_2_18.png"], ("physical", "colocated"),
       quote="Again, the highest stressed areas coincide with the most damaged ones.",
       related=["figure_2_17_t2.png"], subject=("stress", "damage")),
    _f("2.19", "2.3-ex3", "cantilever on a foundation", ["figure_2_19.png"],
       kind="setting"),
    _f("2.20", "2.3-ex3", "von Mises at t = 0 and t = 0.5: same forces, larger "
       "deformation", ["figure_2_20_t0.png", "figure_2_20_t0.5.png"], ("deformation_grows",),
       quote="Due to this fact, at time t = 0.5, the forces are the same as at the initial time "
       "but the deformations have increased.", subject=("configuration",)),
    _f("2.21", "2.3-ex3", "von Mises and damage at t = 1: load removed but 'the "
       "configuration is not the stress-free one'", ["figure_2_21.png"],
       ("displaced",),
       quote="although the forces have vanished, at final time the configuration is not the "
       "stress-free one", subject=("configuration",)),
    _f("2.22", "2.4-ex1", "unit square, mesh for n = 8", ["figure_2_22_tresca.png"],
       kind="setting", thesis_run="n = 8"),
    _f("2.23", "2.4-ex1", "errors against h + k, Tresca (left) and Coulomb (right)",
       ["figure_2_23_left.png", "figure_2_23_right.png"], kind="convergence"),
    _f("2.24", "2.4-ex1", "Tresca, t = 1, n = 64: 'due to the friction, the highest "
       "stressed area, and the corresponding most damaged one, is located at the right lower "
       "corner'", ["figure_2_24.png"], ("physical", "localised", "min_zeta_lower_right"),
       thesis_run="n = 64, k = 0.002",
       quote="Due to the friction, the highest stressed area, and the corresponding most damaged "
       "one, is located at the right lower corner.", subject=("stress", "damage")),
    _f("2.25", "2.4-ex1", "Coulomb: most stressed/damaged 'at the upper boundary "
       "and at the right lower corner'", ["figure_2_25.png"],
       ("physical", "localised", "min_zeta_top_or_lower_right"), thesis_run="n = 64, k = 0.002",
       quote="We notice now that the highest stressed areas (and so, the most damaged ones) are "
       "located at the upper boundary and at the right lower corner.",
       subject=("stress", "damage")),
    _f("2.26", "2.4-ex2", "unit square without clamping, large friction bound",
       ["figure_2_26.png"], kind="setting"),
    _f("2.27", "2.4-ex2", "deformed mesh at t = 1: 'the contact boundary remains "
       "clamped'", ["figure_2_27.png"], ("bottom_fixed",),
       quote="We notice that the contact boundary remains clamped.", subject=("configuration",)),
    _f("2.28", "2.4-ex2", "most stressed and most damaged 'at the right lower "
       "contact corner'; right upper corner less damaged", ["figure_2_28.png"],
       ("physical", "localised", "min_zeta_lower_right"),
       quote="As it was expected, the highest stressed region and the corresponding most damaged "
       "one, is located at the right lower contact corner with the foundation.",
       subject=("stress", "damage")),
    _f("3.1", "3.1-ex1", "square (0,6)^2 on a deformable foundation",
       ["figure_3_1.png"], kind="setting"),
    _f("3.2", "3.1-ex1", "error against k + h (Table 3.1), linear convergence",
       ["figure_3_2.png"], kind="convergence"),
    _f("3.3", "3.1-ex2", "beam clamped at x = 0 on a deformable foundation",
       ["figure_3_3.png"], kind="setting"),
    _f("3.4", "3.1-ex2", "deformed mesh (x4) at t = 1 with the initial outline; no "
       "penetration into the obstacle", ["figure_3_4.png"], ("no_penetration",), thesis_run="k = 0.01",
       quote="No penetration of the body into the obstacle is produced because of large "
       "deformability coefficient employed", subject=("contact",), amplification=4),
    _f("3.5", "3.1-ex2", "highest stresses and most damaged areas 'near to the "
       "clamped part'", ["figure_3_5.png"], ("physical", "localised", "min_zeta_left"), thesis_run="k = 0.01",
       quote="We notice that the highest stresses and the more damaged areas are located near to "
       "the clamped part.", subject=("stress", "damage")),
    _f("3.6", "3.1-ex3", "L-shaped body on a deformable obstacle",
       ["figure_3_6_undamaged.png"], kind="setting"),
    _f("3.7", "3.1-ex3", "deformed meshes (x10), undamaged and damaged: "
       "'inclusion of the damage effect leads to an increase of the magnitude of the deformation "
       "field' (the 'later time' of the check below is the damaged run)",
       ["figure_3_7_undamaged.png", "figure_3_7_damaged.png"], ("deformation_grows", "as_drawn"),
       thesis_run="k = 0.01",
       quote="Clearly, inclusion of the damage effect leads to an increase of the magnitude of the"
       " deformation field.", subject=("configuration",), amplification=10),
    _f("3.8", "3.1-ex3", "strains at the final time: 'inclusion of the damage "
       "effect leads to an increase of the magnitude of the deformation field'",
       ["figure_3_8_undamaged.png", "figure_3_8_damaged.png"], ("damage_increases_strain",),
       thesis_run="k = 0.01",
       quote="Clearly, inclusion of the damage effect leads to an increase of the magnitude of the"
       " deformation field.", subject=("configuration",)),
    _f("3.9", "3.2-ex1", "unit square, bilateral contact, mesh for n = 8",
       ["figure_3_9.png"], kind="setting", thesis_run="n = 8"),
    _f("3.10", "3.2-ex2", "block between two frictional planes",
       ["figure_3_10.png"], kind="setting"),
    _f("3.11", "3.2-ex2", "deformed mesh (x5): 'the lower part of the contact "
       "boundary remains fixed'", ["figure_3_11.png"], ("bottom_fixed", "as_drawn"),
       quote="We notice that the lower part of the contact boundary remains fixed because of the "
       "size of the friction bound.", subject=("configuration",), amplification=5),
    _f("3.12", "3.2-ex2", "'correspondence between the more stressed areas and the "
       "most damaged ones'", ["figure_3_12.png"], ("physical", "colocated"),
       quote="We observe, as expected, the correspondence between the more stressed areas and the "
       "most damaged ones.", subject=("stress", "damage")),
    _f("3.13", "3.2-ex3", "block on a slope held by an obstacle (left), deformed "
       "configuration (right)", ["figure_3_13_left.png", "figure_3_13.png"]),
    _f("3.14", "3.2-ex3", "'the contacting zones are the more stressed areas and "
       "therefore, the most damaged ones'", ["figure_3_14.png"],
       ("physical", "contact_bands"),
       quote="We notice again that the contacting zones are the more stressed areas and therefore,"
       " the most damaged ones.", subject=("contact", "stress", "damage")),
    _f("3.15", "3.3-ex1", "square (0,6)^2 setting", ["figure_3_15.png"],
       kind="setting"),
    _f("3.16", "3.3-ex1", "error against k + h (Table 3.3, not set beside ours)",
       ["figure_3_16.png"], kind="convergence"),
    _f("3.17", "3.3-ex2", "damage on x2 = 3 at several times (self-mending in the "
       "centre, minima at the edges) and zeta(0, 6) reaching ζ* in finite time",
       ["figure_3_17.png"], ("probe_reaches_star", "minimum_at_edges"), event="zeta_star_reached",
       quote="It is found that there is self-mending in the center, and after some time the "
       "maximal damage (i.e., the minimum point of the damage field ζ) is located at the "
       "edge points", subject=("damage",)),
    _f("3.18", "3.3-ex2", "the same for the initial damage b, on x2 = 0",
       ["figure_3_18.png"], ("probe_reaches_star", "minimum_at_edges"), event="zeta_star_reached",
       quote="As above, after some time the maximal damage is located at the edge points",
       subject=("damage",)),
    _f("3.19", "3.3-ex3", "wrench on a stiff screw, cyclic traction",
       ["figure_3_19.png"], kind="assumed-setting"),
    _f("3.20", "3.3-ex3", "deformed mesh (x2) at T; 'negligible amount of "
       "interpenetration'", ["figure_3_20.png"], ("no_penetration",),
       quote="As can be seen, the normal compliance contact condition caused a negligible amount "
       "of interpenetration between the wrench and the screw.", subject=("contact",),
       amplification=2),
    _f("3.21", "3.3-ex3", "von Mises at T: highest 'at the central region where the "
       "wrench bends'", ["figure_3_21.png"], ("stress_central",),
       quote="The highest stress area is located, as expected, at the central region where the "
       "wrench bends.", subject=("stress",)),
    _f("3.22", "3.3-ex3", "damage at T: 'the highest damage coincides with the "
       "highest stress'", ["figure_3_22.png"], ("physical", "colocated"),
       quote="We note that the highest damage coincides with the highest stress.",
       related=["figure_3_21.png"], subject=("stress", "damage")),
]


def figure_number(filename: str):
    """'figure_2_12_left.png' -> (2, 12, 'left'); None for other PNGs."""
    m = re.match(r"figure_(\d+)_(\d+)(?:_(.*))?\.png$", Path(filename).name)
    return (int(m.group(1)), int(m.group(2)), m.group(3) or "") if m else None


#: what a thesis figure draws beside the body (figstyle.draw_guides), by our PNG name, in the
#: undeformed coordinates of the run: the frictional planes of 2.12/2.13 and 3.11/3.12, the
#: contact part of 2.17/2.18, the foundation of 2.20/2.21 and of 3.4/3.5, the obstacle of
#: 3.7/3.8 and the slope plane and obstacle of 3.13 (drawn in the slope-aligned frame of the
#: run, x1 up the slope)
_PLANES_2_2 = [{"line": [[0.0, 0.0], [4.0, 0.0]], "label": "the lower frictional plane (g1 = 45)"},
               {"line": [[0.0, 4.0], [4.0, 4.0]],
                "label": "the upper frictional plane (g2 = 1000)"}]
_PLANES_3_2 = [{"line": [[0.0, 0.0], [4.0, 0.0]], "label": "the lower frictional plane (g = 1000)"},
               {"line": [[0.0, 2.0], [4.0, 2.0]], "label": "the upper frictional plane (g = 1)"}]
_FOUNDATION_2_3_2 = [{"line": [[0.0, 0.0], [0.0, 1.0]],
                      "label": "the foundation (contact part {0}x[0,1])"}]
_FOUNDATION_2_3_3 = [{"line": [[3.0, 0.0], [4.0, 0.0]],
                      "label": "the foundation (contact part [3,4]x{0})"}]
_OBSTACLE_3_1_3 = [{"line": [[1.0, 1.0], [2.0, 1.0]],
                    "label": "the deformable obstacle (contact part [1,2]x{1})"}]
GUIDES = {
    **{name: _PLANES_2_2 for name in ("figure_2_12_left.png", "figure_2_13.png")},
    **{name: _PLANES_3_2 for name in ("figure_3_11.png", "figure_3_12.png")},
    **{name: _FOUNDATION_2_3_2 for name in ("figure_2_17_t0.png", "figure_2_17_t2.png",
                                            "figure_2_18.png")},
    **{name: _FOUNDATION_2_3_3 for name in ("figure_2_20_t0.png", "figure_2_20_t0.5.png",
                                            "figure_2_21.png")},
    **{name: _OBSTACLE_3_1_3 for name in ("figure_3_7_undamaged.png", "figure_3_7_damaged.png",
                                          "figure_3_8_undamaged.png", "figure_3_8_damaged.png")},
    "figure_3_4.png": [{"line": [[0.0, 0.0], [3.0, 0.0]], "label": "the deformable foundation"}],
    "figure_3_5.png": [{"line": [[0.0, 0.0], [3.0, 0.0]], "label": "the deformable foundation"}],
    "figure_3_13.png": [{"line": [[0.0, 0.0], [2.0, 0.0]],
                         "label": "the slope plane (bottom; x1 up the slope, Tresca g = 1)"},
                        {"line": [[0.0, 0.0], [0.0, 1.0]], "label": "the obstacle (left, g = 1)"}],
}

def mesh_drawn(fig: ThesisFigure, command: str, default_n=None) -> str:
    """What mesh our setting figure draws, when the thesis's caption names another ('' when it
    draws the caption's mesh, or the caption names none): the run's ``--n``, else the
    example's default ``default_n``."""
    want = re.search(r"\bn = (\d+)", fig.thesis_run or "")
    if fig.kind != "setting" or not want:
        return ""
    given = re.search(r"--n (\d+)", command or "")
    ours = int(given.group(1)) if given else default_n
    if ours is None or ours == int(want.group(1)):
        return ""
    return (f"drawn on our mesh n = {ours}; the thesis's Figure {fig.number} shows its mesh for "
            f"n = {want.group(1)}")


#: figures that mark the hinges of the arch's collapse mechanism (from its run's summary.json)
HINGE_FIGURES = ("figure_2_8.png", "figure_2_9.png")


def guides(png: str, summary=None) -> list:
    """The guides of one of our PNGs: GUIDES, and the mechanism hinges of the arch (its run's
    summary: position on the centre line, the face that opens)."""
    out = list(GUIDES.get(png, []))
    if png in HINGE_FIGURES and summary:
        out += [{"point": [h["x_m"], h["y_m"]], "mark": h["opening_face"][0].upper(),
                 "note": "red circles: mechanism hinges (E / I: the extrados / intrados opens)"}
                for h in summary.get("hinges", []) if h.get("mechanism")]
    return out
