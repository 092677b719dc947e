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
    counts = re.search(r"\*\*of (\d+) thesis tables and figures, (\d+) reproduce a result on "
                       r"the stated data, (\d+) reproduce it only under a reading \(departures "
                       r"named\), (\d+) are only a drawing of the stated geometry and (\d+) a "
                       r"drawing of an assumed one; (\d+) not visible in the figure, (\d+) differ, "
                       r"(\d+) not comparable; (\d+) verdicts are judged on quick", md)
    assert counts and sum(map(int, counts.groups()[1:8])) == int(counts.group(1))
    assert int(counts.group(9)) >= 1 and md.index("Preview") < md.index("- [Summary")
    # one source: every table verdict of fidelity.md is the summary row's verdict
    from reproduction.verdicts import md_cell
    fidelity = json.loads((tmp_path / "fidelity" / "fidelity.json").read_text())
    for t in fidelity["tables"]:
        assert f"| {md_cell(t['verdict'])} |" in md, t["table"]
        if t.get("departures"):
            assert t["verdict"].startswith(("reproduced under a reading", "differs")), t["table"]
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


def _square(n=8):
    import numpy as np
    xs = np.linspace(0.0, 1.0, n + 1)
    return np.array([[(xs[i], xs[j]), (xs[i + 1], xs[j]), (xs[i + 1], xs[j + 1])]
                     for i in range(n) for j in range(n)])


def _panel(tmp_path, name, cells, zeta, stress=None, disp=None, amplification=1.0):
    """A figure's panel data as a run saves them (deformed cells, stress, damage)."""
    from damage_dolfinx.viz import figstyle
    stress = 1e6 * (2 - cells[..., 1].mean(1)) if stress is None else stress
    xy = cells if disp is None else cells + amplification * disp
    panels = [dict(xy=xy, values=stress, name="von_mises", label="von Mises stress [Pa]"),
              dict(xy=xy, values=zeta, name="zeta", label="damage zeta")]
    figstyle.save_panels(tmp_path / f"{name}.png", panels, title="t",
                         amplification=amplification, zeta_star=0.01, ref_xy=cells)
    return tmp_path / f"{name}{figstyle.PANEL_SUFFIX}"


def _run_folder(tmp_path, name, status="completed", t_final=1.0, departures=()):
    """A run folder as the runner writes it: summary.json (with its reading record) and
    history.csv."""
    folder = tmp_path / name
    folder.mkdir()
    summary = {"example": "9.9-ex1", "status": status, "t_final": t_final, "T": 1.0,
               "parameters": {"zeta_star": 0.01}, "assumptions": [],
               "reading": {"name": "evidence", "default": True, "departures": list(departures)}}
    (folder / "summary.json").write_text(json.dumps(summary))
    (folder / "history.csv").write_text("step,t,u_L2\n0,0,1.0\n1,%g,0.2\n" % t_final)
    return folder


def test_planted_departure_reaches_the_figure_verdict(tmp_path):
    """A run that records a departure in summary.json is never plain 'reproduced': its figure
    is 'reproduced under a reading', with the departure and its basis named."""
    from reproduction.checks import judge, run_context
    from reproduction.classes import category
    from reproduction.figures import ThesisFigure
    cells = _square()
    strong = _panel(tmp_path, "strong", cells, 0.2 + 0.8 * cells[..., 1])
    fig = ThesisFigure("9.9", "9.9-ex1", "", ("a.png",), ("physical", "colocated"),
                      subject=("stress", "damage"))
    fitted = {"what": "kappa = 0.003 instead of kappa = 1", "basis": "fitted", "fitted": True,
              "against_text": False, "source": "reading", "text": "..."}
    context = dict(run_context(_run_folder(tmp_path, "run", departures=[fitted])), T_full=1.0)
    verdict = judge(fig, [strong], context=context)[0]
    assert category(verdict) == "reproduced under a reading", verdict
    assert "kappa = 0.003 instead of kappa = 1 (fitted)" in verdict
    plain = dict(run_context(_run_folder(tmp_path, "plain")), T_full=1.0)
    assert category(judge(fig, [strong], context=plain)[0]) == "reproduced"


def test_planted_early_stop_is_not_comparable(tmp_path):
    """A run that stops before the thesis's final time is never evidence: 'not comparable',
    whether it was cut (a quick run's --T) or stopped on its own; a stop at the event the
    thesis's statement is about (the arch's collapse) is not early."""
    from reproduction.checks import judge, run_context
    from reproduction.classes import category
    from reproduction.figures import ThesisFigure
    cells = _square()
    strong = _panel(tmp_path, "strong", cells, 0.2 + 0.8 * cells[..., 1])
    fig = ThesisFigure("9.9", "9.9-ex1", "", ("a.png",), ("physical", "colocated"),
                      subject=("stress", "damage"))
    stopped = dict(run_context(_run_folder(tmp_path, "stop", "zeta_star_reached", 0.4)),
                   T_full=1.0)
    verdict = judge(fig, [strong], context=stopped)[0]
    assert category(verdict) == "not comparable" and "t = 0.4 of the thesis's T = 1" in verdict
    cut = dict(run_context(_run_folder(tmp_path, "cut")), T_full=1.0, T_run=0.5)
    assert category(judge(fig, [strong], context=cut)[0]) == "not comparable"
    event = ThesisFigure("9.9", "9.9-ex1", "", ("a.png",), ("physical", "colocated"),
                         event="collapse", subject=("stress", "damage"))
    collapse = dict(run_context(_run_folder(tmp_path, "collapse", "collapse", 0.02)), T_full=0.3)
    assert category(judge(event, [strong], context=collapse)[0]) == "reproduced"


def test_planted_differs_whose_feature_holds(tmp_path):
    """Figure 2.12's statement (top edge clamped, bottom edge moves) is about the configuration
    the thesis draws x3: a slide of a fraction of the body holds; a 16 m slide of a 4 m square
    (x3: twelve times the body) is not that configuration and differs, quoting our numbers; a
    moving top differs too."""
    import numpy as np
    from reproduction.checks import judge
    from reproduction.classes import category
    from reproduction.figures import THESIS_FIGURES
    fig = next(f for f in THESIS_FIGURES if f.number == "2.12")
    cells = 4 * _square()
    context = {"T_full": 5.0, "status": "completed", "t_final": 5.0, "departures": []}
    disp = np.zeros_like(cells)
    for slide, expected in ((0.16, "reproduced"), (16.0, "differs")):
        disp[..., 0] = slide * (1 - cells[..., 1] / 4)      # bottom slides, top fixed
        npz = _panel(tmp_path, f"slide{slide}", cells, np.ones(cells.shape[:2]), disp=disp,
                     amplification=3.0)
        verdict = judge(fig, [npz], context=context)[0]
        assert category(verdict) == expected, verdict
        if expected == "reproduced":
            assert "top edge 0.00, bottom edge 1.00 of max |u|" in verdict
    assert "x3 (the thesis's factor) gives 8.5 times its size" in verdict
    disp[..., 0] = 0.16 * cells[..., 1] / 4                  # the top moves: the statement fails
    npz = _panel(tmp_path, "top", cells, np.ones(cells.shape[:2]), disp=disp, amplification=3.0)
    verdict = judge(fig, [npz], context=context)[0]
    assert category(verdict) == "differs" and "top edge 1.00, bottom edge 0.00" in verdict


def test_planted_vacuous_premises_fail(tmp_path):
    """A check counts only when its premise holds. No penetration without contact (Figure
    3.4's beam off its foundation) fails with that reason; a damage pattern inside a body at
    zeta* nearly everywhere (a runaway) fails with that reason; with the premise holding the
    same data pass."""
    import numpy as np
    from reproduction.checks import judge, run_context
    from reproduction.classes import category
    from reproduction.figures import THESIS_FIGURES, ThesisFigure
    cells = _square()
    fig_3_4 = next(f for f in THESIS_FIGURES if f.number == "3.4")
    npz = _panel(tmp_path, "beam", cells, np.ones(cells.shape[:2]),
                 disp=0.01 * np.ones_like(cells), amplification=4.0)
    for length, expected in ((0.0, "differs"), (0.4, "reproduced")):
        folder = _run_folder(tmp_path, f"beam{length}")
        (folder / "history.csv").write_text(
            "step,t,u_L2,penetration_rms,contact_length\n0,0,0,0,0.5\n1,1,0.2,0,%g\n" % length)
        context = dict(run_context(folder), T_full=1.0)
        verdict = judge(fig_3_4, [npz], context=context)[0]
        assert category(verdict) == expected, verdict
    assert "premise fails: no contact at the final time" not in verdict
    folder = _run_folder(tmp_path, "beam_off")
    (folder / "history.csv").write_text("step,t,u_L2,penetration_rms,contact_length\n"
                                        "0,0,0,0,0.5\n1,1,0.2,0,0\n")
    verdict = judge(fig_3_4, [npz], context=dict(run_context(folder), T_full=1.0))[0]
    assert "premise fails: no contact at the final time" in verdict, verdict
    colocated = ThesisFigure("9.9", "x", "", ("a.png",), ("colocated",),
                             subject=("stress", "damage"))
    pattern = 0.2 + 0.8 * cells[..., 1]                     # ranks with the stress
    assert category(judge(colocated, [_panel(tmp_path, "pattern", cells, pattern)])[0]) == \
        "reproduced"
    runaway = 0.01 + 0.01 * cells[..., 1]                   # at zeta* everywhere, same ranks
    verdict = judge(colocated, [_panel(tmp_path, "runaway", cells, runaway)])[0]
    assert category(verdict) == "differs" and "premise fails" in verdict, verdict
    assert "a pattern inside a fully damaged body proves nothing" in verdict


def test_statement_subjects_rule_the_checks(tmp_path):
    """A statement about the configuration is not judged by the damage's one-colour rule
    (Figure 2.21 with a faint damage field is reproduced, not 'not visible'); a check of another
    subject than the statement's is refused; a 'nothing to test' beside a quoted statement is
    refused; every quoted statement of the catalogue of figures is tested."""
    import numpy as np
    from reproduction.checks import judge
    from reproduction.classes import Evidence, category, classify
    from reproduction.figures import THESIS_FIGURES, ThesisFigure, validate
    cells = _square()
    fig_2_21 = next(f for f in THESIS_FIGURES if f.number == "2.21")
    faint = _panel(tmp_path, "faint", cells, 0.95 + 0.04 * cells[..., 1],
                   disp=0.01 * np.ones_like(cells))
    context = {"u_L2_first": 0.0, "u_L2_last": 0.5, "u_L2_max": 1.0}
    verdict = judge(fig_2_21, [faint], context=context)[0]
    assert category(verdict) == "reproduced", verdict
    wrong = ThesisFigure("9.9", "x", "", ("a.png",), ("displaced", "colocated"),
                         quote="the configuration is not the stress-free one",
                         subject=("configuration",))
    with pytest.raises(ValueError, match="colocated"):
        judge(wrong, [faint], context=context)
    quoted = ThesisFigure("9.9", "x", "", ("a.png",), (), quote="the highest stress is central")
    with pytest.raises(ValueError, match="quotes a statement"):
        validate(quoted)
    with pytest.raises(ValueError, match="refused"):
        classify(Evidence(statement=False, quote="the highest stress is central"))
    for fig in THESIS_FIGURES:
        validate(fig)
        assert not fig.quote or fig.checks or fig.kind != "field", fig.number


def test_visibility_and_statement_rules(tmp_path):
    """'not visible' only when every check holds and the damage spans under 5 % of [zeta*, 1];
    a field over a fifth of the scale is visible; no damage at all fails a damage statement;
    a figure without a statement of its own is not comparable."""
    import numpy as np
    from reproduction.checks import judge
    from reproduction.classes import category
    from reproduction.figures import THESIS_FIGURES, ThesisFigure
    cells = _square()
    fig = ThesisFigure("9.9", "x", "", ("a.png",), ("physical", "colocated"),
                       subject=("stress", "damage"))
    faint = _panel(tmp_path, "faint", cells, 0.95 + 0.04 * cells[..., 1])
    verdict = judge(fig, [faint])[0]
    assert category(verdict) == "not visible in this figure" and "rank together" in verdict
    fifth = _panel(tmp_path, "fifth", cells, 0.75 + 0.2 * cells[..., 1])
    assert category(judge(fig, [fifth])[0]) == "reproduced"
    wrong = _panel(tmp_path, "wrong", cells, 1.0 - 0.8 * cells[..., 1])
    assert category(judge(fig, [wrong])[0]) == "differs"
    none = _panel(tmp_path, "none", cells, np.full(cells.shape[:2], 0.99995))
    assert category(judge(fig, [none])[0]) == "differs"
    fig_2_4 = next(f for f in THESIS_FIGURES if f.number == "2.4")
    assert category(judge(fig_2_4, [faint])[0]) == "not comparable"


def test_quick_verdicts_and_table_departures():
    """A quick verdict ends in '(quick)'; a table on data with a departure (Table 2.4's norm)
    is 'reproduced under a reading' and says what the match depends on."""
    import sys
    from reproduction import CHECKOUT
    from reproduction.classes import QUICK, Evidence, category, classify
    sys.path.insert(0, str(CHECKOUT / "benchmarks" / "reproduction"))
    import fidelity
    checks = [("errors of the thesis's size", True, "median 0.7"), ("rate", True, "0.78 against 0.81")]
    assert classify(Evidence(kind="table", checks=checks, quick=True)).endswith(QUICK)
    entry = {"thesis_norm": "H1 (V) norm", "our_error": "max_n (||u - u_hk||_V + ||zeta - zeta_hk||_L2)",
             "component_medians": {"error_u_V": 0.27}}
    deps = fidelity.norm_departures(entry)
    verdict = classify(Evidence(kind="table", checks=checks, departures=deps))
    assert category(verdict) == "reproduced under a reading" and "0.27x" in verdict


def test_runs_record_their_departures():
    """summary.json's reading record (written by every run) carries the departures from the
    stated text with their basis, including the stated values our data contradict."""
    from damage_dolfinx.core import departures
    from damage_dolfinx.catalogue import examples
    rec = departures.record(examples.get("2.3-ex1"))
    assert rec["name"] == "literal" and rec["departures"][0]["against_text"]
    assert "c_nu = 1e10" in rec["departures"][0]["what"]
    rec = departures.record(examples.get("3.2-ex1"))
    assert rec["name"] == "evidence" and any(d["fitted"] for d in rec["departures"])
    assert departures.record(examples.get("2.1-ex1"))["departures"] == []
    for ex in examples.catalogue().values():   # the label of each reading counts them all
        n = len(departures.record(ex)["departures"])
        assert (f"{n} departure(s)" in ex.assumptions[0]) == (n > 0), ex.id


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


def test_one_record_per_item_planted_disagreement(tmp_path, monkeypatch):
    """Every place that states an item's verdict prints it from one record: a second verdict
    for an item is refused; a hand-written verdict in the readings section that differs from the
    record stops the report; the committed readings state no verdict of their own, and the
    report prints the record's beside each of their figure rows."""
    from reproduction import CHECKOUT
    from reproduction.record import VerdictRecord, stated
    record = VerdictRecord()
    record.set("Figure 2.12", "differs: the thesis says: x; ours: y")
    record.set("Figure 2.12", "differs: the thesis says: x; ours: y")   # the same: fine
    with pytest.raises(ValueError, match="two verdicts"):
        record.set("Figure 2.12", "reproduced: x")
    record.set("Figure 3.4", "reproduced: penetration 0 m")
    planted = ("| figure | setting | analysis |\n|---|---|---|\n"
               "| 2.12 / 3.4 | n = 40 | **reproduced**: the edges agree |\n\n"
               "In one line: **3.4 differs** (the beam leaves its foundation).\n")
    assert sorted(record.disagreements(planted)) == [
        "text: Figure 2.12 stated as 'reproduced', the record says 'differs'",
        "text: Figure 3.4 stated as 'differs', the record says 'reproduced'"]
    filled = record.fill_readings(planted)
    assert "verdict (this report) |" in filled
    assert ("[Figure 2.12](#fig-2-12): **differs**; [Figure 3.4](#fig-3-4): **reproduced** |"
            in filled)
    committed = (CHECKOUT / "benchmarks" / "readings.md").read_text()
    assert stated(committed) == []                     # no verdict of its own
    readings = tmp_path / "readings.md"                # a report whose readings disagree
    readings.write_text(committed + "\n| figure | analysis |\n|---|---|\n| 2.12 | "
                        "**reproduced**: planted |\n")
    from reproduction import build as report
    monkeypatch.setattr(report, "READINGS", readings)
    with pytest.raises(ValueError, match="Figure 2.12 stated as 'reproduced'"):
        report.build(tmp_path / "results")
    monkeypatch.setattr(report, "READINGS", CHECKOUT / "benchmarks" / "readings.md")
    report.build(tmp_path / "results")
    md = (tmp_path / "results" / "report" / "REPORT.md").read_text()
    rows = {}
    for line in md.splitlines():
        cells = [c.strip() for c in re.split(r"(?<!\\)\|", line)[1:-1]]
        m = re.match(r"\[((?:Figure|Table) [\d.]+)\]\(#", cells[0]) if cells else None
        if m and len(cells) == 5:
            rows[m.group(1)] = cells[4]
    assert len(rows) == 58
    fidelity = (tmp_path / "results" / "fidelity" / "fidelity.md").read_text()
    from reproduction.text import self_contained_problems
    assert self_contained_problems(tmp_path / "results" / "report") == []
    assert len({item for item, _ in stated(md)}) >= 50 and stated(fidelity, default_kind="Table")
    for item, cls in stated(md) + stated(fidelity, default_kind="Table"):
        assert rows[item].startswith(cls), (item, cls, rows[item])


def test_no_claim_about_tables_the_project_has_not(tmp_path):
    """No text of the product, the records or the report claims agreement with a thesis table
    the project cannot compute against (Tables 2.1 and 3.3): every tracked text file of the
    checkout (the tests, which plant claims, aside) and the assumptions every example prints
    are scanned; a planted claim is found,
    a negated mention is not."""
    from damage_dolfinx.catalogue import examples
    from reproduction import CHECKOUT
    from reproduction.text import assumption, unsupported_claims
    assert unsupported_claims('our errors "\n    "which agree with Tables 2.1 and 3.3 with the 1/2')
    assert unsupported_claims("the rate matches Table 3.3")
    assert unsupported_claims("Table 2.1 is reproduced within 10 %")
    assert not unsupported_claims("our errors are never compared with Tables 2.1 and 3.3")
    assert not unsupported_claims("python benchmarks/reproduction/x.py (Tables 2.1, 3.3)")
    assert not unsupported_claims("convergence (Table 3.3.3) agrees")  # another number
    try:  # the tracked files; a copy without git (the platform roots): every file of the tree
        files = subprocess.run(["git", "ls-files"], cwd=CHECKOUT, capture_output=True,
                               text=True, check=True).stdout.split()
    except (OSError, subprocess.CalledProcessError):
        skip = {".git", ".venv", "build", "results", "__pycache__", ".pytest_cache"}
        files = [p.relative_to(CHECKOUT).as_posix() for p in CHECKOUT.rglob("*")
                 if p.is_file() and not skip & set(p.relative_to(CHECKOUT).parts)]
    found = []
    for name in files:
        path = CHECKOUT / name
        if path.suffix in (".png", ".pdf", ".h5", ".npz", ".xdmf") or not path.is_file() \
                or name.startswith("tests/"):  # the tests plant claims on purpose
            continue
        try:
            text = path.read_text()
        except UnicodeDecodeError:
            continue
        found += [f"{name}: {c}" for c in unsupported_claims(text)]
    for ex in examples.catalogue().values():
        found += [f"{ex.id}: {c}" for a in ex.assumptions
                  for c in unsupported_claims(assumption(a))]
    assert found == [], found


def test_contact_parts_drawn_and_setting_meshes_named():
    """Every field figure whose thesis figure draws a contact part gets it as a guide (the
    frictional planes, the contact part, the foundation, the obstacle), placed on the run's
    contact boundary; a setting figure drawn on another mesh than its caption's says which."""
    from reproduction.figures import THESIS_FIGURES, guides, mesh_drawn
    expected = {  # our PNG: the contact part's end points (undeformed coordinates)
        "figure_2_12_left.png": [[[0, 0], [4, 0]], [[0, 4], [4, 4]]],
        "figure_2_13.png": [[[0, 0], [4, 0]], [[0, 4], [4, 4]]],
        "figure_3_11.png": [[[0, 0], [4, 0]], [[0, 2], [4, 2]]],
        "figure_3_12.png": [[[0, 0], [4, 0]], [[0, 2], [4, 2]]],
        "figure_2_17_t0.png": [[[0, 0], [0, 1]]], "figure_2_17_t2.png": [[[0, 0], [0, 1]]],
        "figure_2_18.png": [[[0, 0], [0, 1]]],
        "figure_2_20_t0.png": [[[3, 0], [4, 0]]], "figure_2_20_t0.5.png": [[[3, 0], [4, 0]]],
        "figure_2_21.png": [[[3, 0], [4, 0]]],
        **{f"figure_3_{n}_{case}.png": [[[1, 1], [2, 1]]] for n in (7, 8)
           for case in ("undamaged", "damaged")},
        "figure_3_4.png": [[[0, 0], [3, 0]]], "figure_3_5.png": [[[0, 0], [3, 0]]],
    }
    for png, lines in expected.items():
        drawn = [g["line"] for g in guides(png) if "line" in g]
        assert drawn == lines and all(g.get("label") for g in guides(png)), png
    assert guides("figure_2_14.png") == []
    fig_2_1 = next(f for f in THESIS_FIGURES if f.number == "2.1")
    assert mesh_drawn(fig_2_1, "damage-dolfinx run 2.1-ex1 --n 5 --quiet", 20) == \
        "drawn on our mesh n = 5; the thesis's Figure 2.1 shows its mesh for n = 10"
    assert mesh_drawn(fig_2_1, "damage-dolfinx run 2.1-ex1 --quiet", 20).startswith(
        "drawn on our mesh n = 20")
    assert mesh_drawn(fig_2_1, "damage-dolfinx run 2.1-ex1 --n 10", 20) == ""
    fig_2_3 = next(f for f in THESIS_FIGURES if f.number == "2.3")   # no mesh in its caption
    assert mesh_drawn(fig_2_3, "damage-dolfinx run 2.1-ex2a --n 5", 20) == ""


def test_figure_3_21_stress_location_is_tested(tmp_path):
    """Figure 3.21 quotes where the highest stress is ('the central region'): it is tested along
    the body's length (its principal axis, so a slanted body is measured along itself)."""
    import numpy as np
    from reproduction.checks import judge
    from reproduction.classes import category
    from reproduction.figures import THESIS_FIGURES
    fig = next(f for f in THESIS_FIGURES if f.number == "3.21")
    cells = _square(8) * np.array([4.0, 0.5])                      # a bar 4 x 0.5 ...
    c, s = np.cos(-0.8), np.sin(-0.8)
    cells = cells @ np.array([[c, s], [-s, c]])                    # ... slanted like the wrench
    along = (cells @ np.array([c, s]))                             # position along the bar
    context = {"T_full": 1.0, "status": "completed", "t_final": 1.0, "departures": []}
    for peak, expected in ((2.0, "reproduced"), (0.3, "differs")):
        stress = 1e6 * np.exp(-(along - peak) ** 2)
        npz = _panel(tmp_path, f"bar{peak}", cells, np.ones(cells.shape[:2]), stress=stress)
        verdict = judge(fig, [npz], context=context)[0]
        assert category(verdict) == expected, verdict
    assert "% of the body's length from its middle" in verdict


def test_planted_check_that_holds_by_construction_carries_no_verdict(tmp_path):
    """The damage within [zeta*, 1] holds by construction (the solver refuses anything else):
    a figure whose statement (stress and damage coincide) is not measured -- no stress in its
    data -- is not comparable, not reproduced on that check alone; with one of two checks of
    its statement unmeasured and none failing, it is not comparable; a failing sanity check
    still makes it differ; with the stress present the same damage is reproduced."""
    import numpy as np
    from damage_dolfinx.viz import figstyle
    from reproduction.checks import judge
    from reproduction.classes import Evidence, category, classify
    from reproduction.figures import ThesisFigure
    cells = _square()
    zeta = 0.2 + 0.8 * cells[..., 1]
    figstyle.save_panels(tmp_path / "z.png", [dict(xy=cells, values=zeta, name="zeta",
                                                   label="damage zeta")],
                         title="t", amplification=1.0, zeta_star=0.01, ref_xy=cells)
    no_stress = tmp_path / f"z{figstyle.PANEL_SUFFIX}"
    fig = ThesisFigure("9.9", "x", "", ("a.png",), ("physical", "colocated"),
                       quote="the highest stress coincides with the highest damage",
                       subject=("stress", "damage"))
    verdict = judge(fig, [no_stress])[0]
    assert category(verdict) == "not comparable", verdict
    assert "only what holds by construction" in verdict, verdict
    assert category(judge(fig, [_panel(tmp_path, "with_stress", cells, zeta)])[0]) == \
        "reproduced"
    two = ThesisFigure("9.9", "x", "", ("a.png",), ("physical", "localised", "colocated"),
                       quote="the damage is concentrated where the stress is highest",
                       subject=("stress", "damage"))
    verdict = judge(two, [no_stress])[0]
    assert category(verdict) == "not comparable" and "part of the statement is not measured" \
        in verdict and "rank together" in verdict, verdict
    bad = classify(Evidence(checks=[("stress and damage rank together", True, "0.9")],
                            sanity=[("the damage within [ζ*, 1]", False, "ζ in [-0.1, 1]")]))
    assert category(bad) == "differs", bad


def test_setting_mesh_note_is_drawn_under_the_figure(tmp_path):
    """reproduction.plots.note_under writes the setting figure with its mesh note under it
    (the image a strip taller, the original kept as drawn), from the run's own copy."""
    import matplotlib.image
    import numpy as np
    from reproduction.plots import note_under
    source, png = tmp_path / "source.png", tmp_path / "figure_2_1.png"
    matplotlib.image.imsave(source, np.full((120, 200, 3), 0.5))
    note_under(png, "drawn on our mesh n = 20; the thesis's Figure 2.1 shows its mesh for n = 10",
               source)
    img = matplotlib.image.imread(png)
    assert img.shape[:2] == (150, 200)
    assert np.allclose(img[:120, :, :3], 0.5, atol=0.02)      # the figure, unchanged
    assert img[120:, :, :3].min() < 0.5                       # the note: dark text on white


def test_planted_checks_that_hold_trivially(tmp_path):
    """No check holds whatever the data: Figure 2.12's drawn-size check fails for a slide the
    thesis's x3 would not show (a micrometre on a 4 m square: the top-fixed, bottom-moving
    ratio alone would still hold); Figure 2.21's statement is about the configuration: judged
    by the displacement left at the final time, a body back at rest differs, a displaced one
    is reproduced whatever its (vanishing) stress -- no 'stress above zero' check, which any
    rounding passes."""
    import numpy as np
    from reproduction.checks import CHECKS, judge
    from reproduction.classes import category
    from reproduction.figures import THESIS_FIGURES
    fig = next(f for f in THESIS_FIGURES if f.number == "2.12")
    cells = 4 * _square()
    context = {"T_full": 5.0, "status": "completed", "t_final": 5.0, "departures": []}
    disp = np.zeros_like(cells)
    disp[..., 0] = 1e-6 * (1 - cells[..., 1] / 4)            # bottom slides a micrometre
    npz = _panel(tmp_path, "micro", cells, np.ones(cells.shape[:2]), disp=disp,
                 amplification=3.0)
    verdict = judge(fig, [npz], context=context)[0]
    assert category(verdict) == "differs" and "is visible" in verdict, verdict
    assert "top edge 0.00, bottom edge 1.00" not in verdict.split("ours:")[0]
    fig_2_21 = next(f for f in THESIS_FIGURES if f.number == "2.21")
    assert fig_2_21.subject == ("configuration",) and "stressed" not in CHECKS
    at_rest = _panel(tmp_path, "at_rest", cells, np.ones(cells.shape[:2]),
                     stress=np.full(cells.shape[:2], 1e-3), disp=0.01 * np.ones_like(cells))
    for last, expected in ((0.001, "differs"), (0.05, "reproduced")):
        context = {"u_L2_first": 0.11, "u_L2_last": last, "u_L2_max": 0.17}
        verdict = judge(fig_2_21, [at_rest], context=context)[0]
        assert category(verdict) == expected, verdict
