"""`make figures` / `make report` machinery: a quick figure run of one example, the report built
from it, and the HTML opened in headless Chromium with every image loading."""
import json
import re
import shutil
import subprocess

import pytest

from damage_dolfinx.report import build as report, reproduce

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
    md = (tmp_path / "REPORT.md").read_text()
    assert "damage-dolfinx run 2.3-ex1" in md          # traceable to its command
    assert "G11" in md and "Observed rate" in md        # assumptions and a convergence table
    text = page.read_text()
    assert 'id="contents"' in text and 'id="summary"' in text   # TOC and summary table
    summary = text[text.index('<table class="summary">'):]
    summary = summary[:summary.index("</table>")]
    links = re.findall(r'href="#([\w.-]+)"', summary)
    anchors = set(re.findall(r'id="([\w.-]+)"', text))
    assert len(links) >= 50 and set(links) <= anchors           # every row links to its anchor
    toc = re.findall(r'href="#([\w.-]+)"', text[:text.index('id="summary"')])
    assert toc and set(toc) <= anchors
    assert re.search(r"\d+ reproduced, \d+ differ, \d+ not comparable", text)
    assert 'id="fig-2-14"' in text and "thesis lines" in text   # the produced figure, captioned
    for anchor in ("performance", "step-floor", "scaling-3d"):  # the benchmark records
        assert f'id="{anchor}"' in text and f'href="#{anchor}"' in text
    assert "step over SpMV" in md and "dofs u" in md     # floor profile and 3-D scaling tables
    _damage_bars_fixed_and_factors_round(tmp_path / "figures", index)
    if CHROMIUM is None:
        pytest.skip("chromium not installed (make setup installs it)")
    loaded, total = _images_in_chromium(page)
    assert total >= 3 and loaded == total
    broken = tmp_path / "broken.html"  # the check can fail: a missing image is reported
    broken.write_text(page.read_text().replace("<body>", '<body><img src="missing.png">', 1))
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
    log = out / "runs" / "2.1-ex1" / "log.txt"
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
    from damage_dolfinx.report import doc as report_doc
    html = report_doc._markdown_to_html("a reading,\n||eps(u)||_L2 = 1e-3, so\n\n| n | k |\n"
                                        "|---|--:|\n| 4 | 0.1 |\n")
    assert html.count("<table>") == 1 and "<p>a reading, ||eps(u)||_L2 = 1e-3, so</p>" in html
