"""`make figures` / `make report` machinery: a quick figure run of one example, the report built
from it, and the HTML opened in headless Chromium with every image loading."""
import re
import shutil
import subprocess

import pytest

from damage_dolfinx import report, reproduce

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
    if CHROMIUM is None:
        pytest.skip("chromium not installed (make setup installs it)")
    loaded, total = _images_in_chromium(page)
    assert total >= 3 and loaded == total
    broken = tmp_path / "broken.html"  # the check can fail: a missing image is reported
    broken.write_text(page.read_text().replace("<body>", '<body><img src="missing.png">', 1))
    loaded, total = _images_in_chromium(broken)
    assert loaded == total - 1
