"""`make figures` / `make report` machinery: a quick figure run of one example, the report built
from it, and the HTML opened in headless Chromium with every image loading."""
import json
import re
import shutil
import subprocess

import pytest

from reproduction import build as report, reproduce

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


def _images_in_chromium(page):
    """(loaded, total) images of an HTML file after its load event, per headless Chromium."""
    proc = subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu",
                           "--virtual-time-budget=10000", "--dump-dom", page.as_uri()],
                          capture_output=True, text=True, timeout=120)
    m = re.search(r'data-images="(\d+)/(\d+)"', proc.stdout)
    assert m, f"the page's load script did not run:\n{proc.stdout[:500]}\n{proc.stderr[-500:]}"
    return int(m.group(1)), int(m.group(2))


def test_quick_figures_and_report(tmp_path):
    index = reproduce.run_figures("quick", tmp_path / "figures", np_=1, only=["2.3-ex1"])
    assert [r["returncode"] for r in index["runs"]] == [0]
    files = {f["file"] for f in index["figures"]}
    assert {"figure_2_14.png", "2.3-ex1_fields_final.png"} <= files
    page = report.build(tmp_path)
    folder = tmp_path / "report"
    assert page == folder / "REPORT.html"
    md = (folder / "REPORT.md").read_text()
    assert "damage-dolfinx run 2.3-ex1" in md          # traceable to its command
    assert "assumed: " in md and "Observed rate" in md  # assumptions and a convergence table
    text = page.read_text()
    assert 'id="contents"' in text and 'id="summary"' in text   # TOC and summary table
    summary = text[text.index('<table class="summary">'):]
    summary = summary[:summary.index("</table>")]
    links = re.findall(r'href="#([\w.-]+)"', summary)
    anchors = set(re.findall(r'id="([\w.-]+)"', text))
    assert len(links) >= 50 and set(links) <= anchors           # every row links to its anchor
    toc = re.findall(r'href="#([\w.-]+)"', text[:text.index('id="summary"')])
    assert toc and set(toc) <= anchors
    counts = re.search(r"\*\*(\d+) reproduced, (\d+) reproduced under a reading, (\d+) setting "
                       r"assumed, (\d+) not visible in this figure, (\d+) differs, (\d+) not "
                       r"comparable\*\* \(of (\d+)\)", md)
    assert counts and sum(map(int, counts.groups()[:6])) == int(counts.group(7))
    assert 'id="fig-2-14"' in text and "§2.3.3, p. 106" in text   # the figure, where in the thesis
    for anchor in ("performance", "step-floor", "scaling-3d"):  # the benchmark records
        assert f'id="{anchor}"' in text and f'href="#{anchor}"' in text
    assert "step over SpMV" in md and "dofs u" in md     # floor profile and 3-D scaling tables
    _damage_bars_fixed_and_factors_round(tmp_path / "figures", index)
    _self_contained(folder, tmp_path)


def _self_contained(folder, tmp_path):
    """The report folder stands alone: no machine path, tracker history or internal code, every
    image inside it; it still displays after a move. The check fails on a planted path."""
    from reproduction.text import self_contained_problems
    assert self_contained_problems(folder) == []
    moved = tmp_path / "elsewhere" / "copy"
    shutil.copytree(folder, moved)
    shutil.rmtree(folder)                      # nothing outside the copy is left to link to
    assert self_contained_problems(moved) == []
    planted = moved / "REPORT.html"
    clean = planted.read_text()
    planted.write_text(clean.replace("<body>", "<body><p>see /work/main/results/x.png</p>", 1))
    assert any("/work/" in p for p in self_contained_problems(moved))
    planted.write_text(clean.replace("<body>", '<body><img src="../figures/figure_2_14.png">', 1))
    assert any("not inside the folder" in p for p in self_contained_problems(moved))
    planted.write_text(clean)
    if CHROMIUM is None:
        pytest.skip("chromium not installed (make setup installs it)")
    loaded, total = _images_in_chromium(planted)
    assert total >= 3 and loaded == total
    broken = moved / "broken.html"  # the check can fail: a missing image is reported
    broken.write_text(clean.replace("<body>", '<body><img src="missing.png">', 1))
    loaded, total = _images_in_chromium(broken)
    assert loaded == total - 1


def _damage_bars_fixed_and_factors_round(out, index):
    """Every field figure of a quick run: the damage colour bar, read back from the drawn
    figure, spans [zeta*, 1] (or reaches below zeta* only where the field does); every
    amplification factor in the index is round."""
    from damage_dolfinx.viz import figstyle
    npzs = sorted((out / "runs").rglob("*" + figstyle.PANEL_SUFFIX))
    assert npzs
    for npz in npzs:
        panels, meta, _ = figstyle.load_panels(npz)
        used = figstyle.render_saved(npz, npz.with_suffix(".check.png"))
        for panel, limits in zip(panels, used):
            if figstyle.is_damage(panel["name"], panel["label"]):
                lo = min(meta["zeta_star"], float(panel["values"].min()))
                assert limits == (lo, max(1.0, float(panel["values"].max()))), npz
    factors = [f["amplification"] for f in index["figures"] if f.get("amplification")]
    assert factors and all(figstyle.is_round(a) for a in factors)


def test_resumed_reproduction_keeps_completed_runs(tmp_path):
    """`make figures RESUME=1`: a completed run is kept (not rerun), a missing one is run, an
    interrupted one goes on from its checkpoint (--restart)."""
    out = tmp_path / "figures"
    first = reproduce.run_figures("quick", out, np_=1, only=["2.1-ex1"])
    log = out / "runs" / "2.1-ex1.log.txt"
    stamp = log.stat().st_mtime_ns
    second = reproduce.run_figures("quick", out, np_=1, only=["2.1-ex1", "2.3-ex1"], resume=True)
    assert log.stat().st_mtime_ns == stamp                      # not rerun
    assert second["runs"][0] == first["runs"][0]
    assert [r["example"] for r in second["runs"]] == ["2.1-ex1", "2.3-ex1"]
    assert {"figure_2_14.png"} <= {f["file"] for f in second["figures"]}
    assert second["wall_time_s"] == round(sum(r["wall_time_s"] for r in second["runs"]), 1)
    # an interrupted 2.3-ex1: drop its index entry, leave a checkpoint -> restarted, not wiped
    index = json.loads((out / "index.json").read_text())
    index["runs"] = [r for r in index["runs"] if r["example"] != "2.3-ex1"]
    (out / "index.json").write_text(json.dumps(index))
    summary = out / "runs" / "2.3-ex1" / "summary.json"  # as a killed run leaves it
    summary.write_text(json.dumps({**json.loads(summary.read_text()), "status": "running"}))
    third = reproduce.run_figures("quick", out, np_=1, only=["2.3-ex1"], resume=True)
    assert "--restart" in third["runs"][0]["command"] and third["runs"][0]["returncode"] == 0
    assert json.loads(summary.read_text())["restarts"]  # went on from its (final) checkpoint


def test_markdown_norm_at_line_start_is_text_not_a_table():
    """benchmarks/readings.md wraps lines that begin with a norm ('||eps(u)||_L2 = ...'): a
    pipe table needs its delimiter row, as in GitHub Markdown."""
    from reproduction import doc as report_doc
    html = report_doc._markdown_to_html("a reading,\n||eps(u)||_L2 = 1e-3, so\n\n| n | k |\n"
                                        "|---|--:|\n| 4 | 0.1 |\n")
    assert html.count("<table>") == 1 and "<p>a reading, ||eps(u)||_L2 = 1e-3, so</p>" in html


def test_verdict_classes_on_synthetic_figures(tmp_path):
    """A damage field that is one colour on the fixed scale is 'not visible in this figure'
    (and the figure gets a panel on the field's range); a failed check 'differs'; a run under a
    fitted reading 'reproduced under a reading' with the departure named."""
    import numpy as np
    from damage_dolfinx.viz import figstyle
    from reproduction.checks import departure, judge
    from reproduction.figures import ThesisFigure
    from reproduction.verdicts import CLASSES, category
    xs = np.linspace(0.0, 1.0, 9)
    cells = np.array([[(xs[i], xs[j]), (xs[i + 1], xs[j]), (xs[i + 1], xs[j + 1])]
                      for i in range(8) for j in range(8)])
    stress = 1e6 * (2 - cells[..., 1].mean(1))              # highest at the bottom (DG0)

    def npz(zeta, name):
        panels = [dict(xy=cells, values=stress, name="von_mises", label="von Mises stress [Pa]"),
                  dict(xy=cells, values=zeta, name="zeta", label="damage zeta")]
        figstyle.save_panels(tmp_path / f"{name}.png", panels, title="t", amplification=1.0,
                             zeta_star=0.01, ref_xy=cells)
        figstyle.render_saved(tmp_path / f"{name}{figstyle.PANEL_SUFFIX}", tmp_path / f"{name}.png")
        return tmp_path / f"{name}{figstyle.PANEL_SUFFIX}"

    fig = ThesisFigure("9.9", "x", "", ("a.png",), ("physical", "colocated"))
    faint = npz(0.95 + 0.04 * cells[..., 1], "faint")       # most damaged at the bottom, narrow
    verdict, got, _ = judge(fig, [faint])
    assert category(verdict) == "not visible in this figure" and "rank together" in verdict
    strong = npz(0.2 + 0.8 * cells[..., 1], "strong")
    assert judge(fig, [strong])[0] == "reproduced"
    wrong = npz(1.0 - 0.8 * cells[..., 1], "wrong")           # most damaged at the top
    assert judge(fig, [wrong])[0].startswith(
        "differs: what the thesis says does not hold in our data: stress and damage")
    fitted = "R1 (evidence reading; FITTED value): kappa = 0.003 instead of kappa = 1 (line 3973). x"
    verdict = judge(fig, [strong], context={"departures": [fitted]})[0]
    assert verdict == "reproduced under a reading: kappa = 0.003 instead of kappa = 1 (fitted)"
    assert category(verdict) in CLASSES
    assert departure(fitted) == "kappa = 0.003 instead of kappa = 1 (fitted)"
    none = npz(np.full(cells.shape[:2], 0.99995), "none")      # no damage: nothing to locate
    assert judge(fig, [none])[0].startswith("not visible in this figure: no damage")


def test_reader_text_and_units():
    """Thesis line numbers become sections and pages, codes their meaning; stresses in MPa."""
    from damage_dolfinx.viz import figstyle
    from reproduction.text import assumption, forbidden, reader_text
    assert reader_text("(thesis line 3973)") == "(thesis §3.2.3, p. 176)"
    assert assumption("G6: kappa = 1e-2 (missing in the thesis)") == \
        "assumed: kappa = 1e-2 (missing in the thesis)"
    assert reader_text("see issue 18, sixth session: x") == "see x"
    assert forbidden(reader_text("--out /work/main/results/a/b.png", [("/work/main", "")])) == []
    assert figstyle.si_unit("von Mises stress [Pa]", 2.9e7) == ("von Mises stress [MPa]", 1e6)
    assert figstyle.si_unit("strain [-]", 2e-3) == ("strain [-]", 1.0)
