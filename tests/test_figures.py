"""Figure style rules: damage colour bars never autoscaled, amplification factors
round, one stress scale within a thesis pair, and the fidelity comparison of the thesis tables."""
import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from damage_dolfinx.catalogue import examples
from damage_dolfinx.viz import figstyle
from damage_dolfinx.runtime import runner

REPO = Path(__file__).resolve().parents[1]


def test_amplification_factors_are_round():
    assert [figstyle.round_amplification(a) for a in (9.70774, 0.119338, 0.0361382, 525.49,
                                                      16.7, 1.0, 50.0)] == \
        [5.0, 0.1, 0.02, 500.0, 10.0, 1.0, 50.0]
    assert not figstyle.is_round(16.7) and figstyle.is_round(200.0) and figstyle.is_round(0.05)
    assert "shrunk" in figstyle.amplification_text(0.05)
    assert "×5" in figstyle.amplification_text(5.0)
    for ex in examples.catalogue().values():  # every fixed factor of the catalogue
        for fig in ex.figures:
            if fig.amplification is not None:
                assert figstyle.is_round(fig.amplification), (ex.id, fig.filename)


def _damage_limits(npz):
    panels, meta, _ = figstyle.load_panels(npz)
    used = figstyle.render_saved(npz, Path(npz).with_suffix(".again.png"))
    return [(p, lim) for p, lim in zip(panels, used) if figstyle.is_damage(p["name"], p["label"])]


def test_damage_colour_bar_is_fixed_on_a_small_run(tmp_path):
    """A short 3.2-ex2 run (damage hardly moves from 1): the damage bar still spans
    [zeta*, 1], read back from the figure's colour limits; its amplification is round."""
    summary = runner.run("3.2-ex2", tmp_path, n=4, T=0.05, progress=False)
    figures = {f["file"]: f for f in summary["outputs"]["figures"]}
    zeta_star = summary["parameters"]["zeta_star"]
    (panel, limits), = _damage_limits(tmp_path / "figure_3_12.panel.npz")
    assert np.min(panel["values"]) > 0.5                     # the field is nearly sound ...
    assert limits == (zeta_star, 1.0)                        # ... the bar is not autoscaled
    assert figures["figure_3_12.png"]["amplification"] == 5.0  # the factor of its pair 3.11
    _, meta, _ = figstyle.load_panels(tmp_path / "figure_3_11.panel.npz")
    assert meta["mesh_only"] and meta["amplification"] == 5.0   # deformed mesh, no colour field


def test_damage_below_zeta_star_widens_the_bar_and_says_so(tmp_path):
    xy = np.array([[[0, 0], [1, 0], [1, 1]], [[0, 0], [1, 1], [0, 1]]], float)
    panels = [{"xy": xy, "values": np.array([[1.0, 0.5, -0.2], [1.0, -0.2, 0.9]]),
               "name": "zeta", "label": "damage zeta [-]"},
              {"xy": xy, "values": np.array([3.0, 7.0]), "name": "von_mises",
               "label": "von Mises stress [Pa]"}]
    used = figstyle.render_fields(panels, tmp_path / "f.png", zeta_star=0.01, amplification=16.7)
    assert used[0] == (-0.2, 1.0) and used[1] == (0.0, 7.0)
    vmin, vmax, note = figstyle.damage_limits(panels[0]["values"], 0.01)
    assert "min" in note and "-0.2" in note


def test_pair_shares_the_stress_scale(tmp_path):
    xy = np.array([[[0, 0], [1, 0], [1, 1]]], float)
    for name, s in (("a", 3.0), ("b", 9.0)):
        panels = [{"xy": xy, "values": np.array([s]), "name": "von_mises", "label": "von Mises"},
                  {"xy": xy, "values": np.array([[1.0, 0.9, 0.8]]), "name": "zeta", "label": "zeta"}]
        figstyle.save_panels(tmp_path / f"{name}.png", panels, title=name, amplification=1.0,
                             zeta_star=0.01, mesh_only=False)
    a, b = figstyle.render_pair(tmp_path / "a.panel.npz", tmp_path / "b.panel.npz", tmp_path / "a.png",
                                tmp_path / "b.png")
    assert a[0] == b[0] == (0.0, 9.0) and a[1] == b[1] == (0.01, 1.0)


def test_fidelity_reads_the_tables_and_our_studies(tmp_path):
    sys.path.insert(0, str(REPO / "benchmarks" / "reproduction"))
    import fidelity
    assert fidelity.thesis_tables()[1] == REPO / "benchmarks" / "thesis_tables.json"  # ours only
    shared = json.loads(fidelity.LOCAL_TABLES.read_text())
    result = fidelity.compare(tmp_path)  # no results folder: the committed studies
    tables = {t["table"]: t for t in result["tables"]}
    assert set(tables) == {"2.4", "2.5", "2.6", "2.7", "3.1", "3.2"}
    t = tables["2.4"]
    cell = next(c for c in t["cells"] if c["n"] == 8 and c["k"] == 0.02)
    assert cell["thesis"] == shared["tables"]["2.4"]["rows"]["8"][0]
    assert math.isclose(cell["ratio"], cell["ours"] / cell["thesis"])
    assert t["n_common"] == 25 and t["ratio_min"] <= t["ratio_median"] <= t["ratio_max"]
    assert all(t["verdict"] for t in tables.values())
    fidelity.write(result, tmp_path / "fid")
    assert "| 2.4 |" in (tmp_path / "fid" / "fidelity.md").read_text()


@pytest.mark.parametrize("name", ["figure_2_24_25.png", "figure_3_17_18.png"])
def test_one_file_per_thesis_figure(name):
    from reproduction import reproduce
    variants = {"figure_2_24_25.png": ("2.4-ex1", "tresca", "coulomb"),
                "figure_3_17_18.png": ("3.3-ex2", "a", "b")}[name]
    ex, *vs = variants
    files = {reproduce._figure_name(name, reproduce.Job(ex, v)) for v in vs}
    assert files == ({"figure_2_24.png", "figure_2_25.png"} if ex == "2.4-ex1"
                     else {"figure_3_17.png", "figure_3_18.png"})


def test_setting_figure_draws_loads_and_supports(tmp_path, monkeypatch):
    """Figure 2.19 (2.3-ex3): the load (0, -10) on the top face for t <= 0.5 is drawn as
    arrows at t = 0.5 pushing on Gamma_N; Gamma_D and Gamma_C carry the support hatching."""
    from mpi4py import MPI
    seen = {}
    draw = figstyle.draw_setting
    monkeypatch.setattr(figstyle, "draw_setting",
                        lambda ax, cells, parts, loads=(), note="", split=None: seen.update(
                            parts=parts, loads=loads, note=note) or draw(ax, cells, parts, loads,
                                                                         note, split))
    ex = examples.get("2.3-ex3")
    stepper = ex.build(MPI.COMM_SELF, n=4)
    fig = next(f for f in ex.figures if f.kind == "mesh")
    runner.draw_figure(ex, fig, stepper, tmp_path)
    assert (tmp_path / "figure_2_19.png").is_file() and not seen["note"]
    (kind, segs, vectors, label), = seen["loads"]
    assert kind == "f_N" and len(segs) >= 4 and np.allclose(vectors, [0.0, -10.0])
    assert np.allclose(segs[:, :, 1], 1.0)                      # on the top face
    assert "$t$ = 0.5" in label and "10" in label
    hatched = {label.split()[0]: h for _, _, label, h in seen["parts"]}
    assert hatched == {"Gamma_D": True, "Gamma_N": False, "Gamma_C": True}


def test_traction_arrows_push_onto_and_pull_away_from_the_body():
    square = np.array([[[0, 0], [1, 0], [1, 1]], [[0, 0], [1, 1], [0, 1]]], float)
    inside = figstyle.inside_test(square)
    right = np.array([[[1.0, 0.0], [1.0, 1.0]]])
    tails, deltas = figstyle.traction_arrows(right, [[2.0, 0.0]], inside, 0.1)   # pull
    assert np.allclose(tails, [[1.0, 0.5]]) and deltas[0, 0] > 0
    tails, deltas = figstyle.traction_arrows(right, [[-2.0, 0.0]], inside, 0.1)  # push
    assert np.allclose(tails + deltas, [[1.0, 0.5]]) and tails[0, 0] > 1.0
    tails, deltas = figstyle.traction_arrows(right, [[0.0, 3.0]], inside, 0.1)   # shear: outside
    assert np.all(tails[:, 0] > 1.0) and np.allclose(deltas, [[0.0, 0.3]])


def test_convergence_error_label_in_mathtext():
    assert figstyle.error_mathtext("max_n (||u - u_hk||_V + ||zeta - zeta_hk||_L2)") == \
        r"$\max_n\, (\Vert u - u^{hk}\Vert_{V} + \Vert \zeta - \zeta^{hk}\Vert_{L^2})$"
    assert figstyle.mathtext("Gamma_D (clamped)") == r"$\Gamma_D$ (clamped)"


def test_every_plot_goes_through_figstyle():
    """No module draws with matplotlib directly: figure sizes, fonts, mathtext, colour scales and
    layout come from figstyle (and figbody, its drawing of a body's edges, fields and guides,
    reached through figstyle)."""
    import re
    files = list((REPO / "damage_dolfinx").rglob("*.py")) + list((REPO / "benchmarks").rglob("*.py"))
    direct = [p.name for p in files if p.name not in ("figstyle.py", "figbody.py") and
              re.search(r"^\s*(import matplotlib|from matplotlib)|\.savefig\(|plt\.subplots",
                        p.read_text(), re.M)]
    assert not direct, direct


def test_readable_amplification_one_colour_map_and_distinct_ticks():
    """A factor that would draw the largest displacement beyond half the body's size is replaced
    (the note says which); a fully damaged body gets no stretched panel; ticks over a narrow
    range are distinct numbers; outline edges no part covers are traction-free."""
    import numpy as np
    from damage_dolfinx.viz import figscales, figstyle
    xs = np.linspace(0.0, 4.0, 5)
    cells = np.array([[(xs[i], xs[j]), (xs[i + 1], xs[j]), (xs[i + 1], xs[j + 1])]
                      for i in range(4) for j in range(4)])
    disp = np.zeros_like(cells)
    disp[..., 0] = 16.0 * (1 - cells[..., 1] / 4)          # 16 m slip of a 4 m square
    panels = [dict(xy=cells + 3.0 * disp, values=np.ones(len(cells)))]
    scaled, factor, note = figstyle.readable(panels, cells, 3.0)
    drawn = np.abs(scaled[0]["xy"] - cells).max()
    assert factor < 3.0 and "×3 asked for" in note and drawn <= 0.5 * np.hypot(4, 4)
    small = [dict(xy=cells + 0.01 * disp, values=np.ones(len(cells)))]
    assert figstyle.readable(small, cells, 0.01)[1:] == (0.01, "")  # readable: kept
    assert not figscales.narrow_damage(0.010, 0.012, 0.01)        # fully damaged: no panel
    assert figscales.narrow_damage(0.95, 0.99, 0.01)
    assert figstyle.STRETCHED_CMAP == figstyle.DAMAGE_CMAP
    d = figscales.range_decimals(0.9999, 1.0)
    labels = [f"{v:.{d}f}" for v in np.linspace(0.9999, 1.0, 4)]
    assert len(set(labels)) == 4
    bottom = figstyle.boundary_edges(cells)
    bottom = bottom[np.all(np.isclose(bottom[..., 1], 0.0), axis=1)]
    free = figstyle._free_edges(cells, [(bottom, "g", "Gamma_C", True)])
    assert len(free) == len(figstyle.boundary_edges(cells)) - len(bottom)
