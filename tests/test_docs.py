"""`make docs`: the site builds with no warning, and every page, opened in headless Chromium,
loads with every image and every internal link (to a file of the site and an anchor in it)."""
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from urllib.parse import unquote, urlsplit

import pytest

from conftest import ENV

ROOT = Path(__file__).resolve().parent.parent
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update",
                  "--disable-sync"]

# Appended to a copy of every page: once the page has loaded, write what it found into the DOM
# (which --dump-dom prints). Lazy images are made eager first, so that every image is fetched.
PROBE = """<script>
for (const img of document.images) img.loading = "eager";
window.addEventListener("load", () => setTimeout(() => {
  const images = Array.from(document.images);
  const probe = document.createElement("pre");
  probe.id = "site-probe";
  probe.textContent = JSON.stringify({
    images: images.length,
    broken: images.filter(i => !(i.complete && i.naturalWidth > 0)).map(i => i.src),
    links: Array.from(document.querySelectorAll("a[href]"), a => a.href),
    resources: Array.from(document.querySelectorAll("script[src], link[href], img[src]"),
                          e => e.src || e.href),
  });
  document.body.appendChild(probe);
}, 200));
</script>"""


def build_site(out, results=None):
    """Build the site into ``out``/html with warnings as errors (the report taken from
    ``results``, default: none); returns (seconds, stderr)."""
    env = dict(ENV, DAMAGE_DOLFINX_DOCS_BUILD=str(out),
               DAMAGE_DOLFINX_RESULTS=str(results or out / "no-results"))
    start = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "sphinx", "-b", "html", "-W", "--keep-going",
                           "-d", str(out / "doctrees"), str(ROOT / "docs"), str(out / "html")],
                          env=env, capture_output=True, text=True, timeout=900)
    seconds = time.perf_counter() - start
    assert proc.returncode == 0, f"sphinx failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-5000:]}"
    return seconds, proc.stderr


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    out = tmp_path_factory.mktemp("docs")
    seconds, stderr = build_site(out)
    warnings = [line for line in stderr.splitlines() if "WARNING" in line or "ERROR" in line]
    print(f"site built in {seconds:.1f} s, {len(warnings)} warnings")
    assert not warnings
    return out / "html"


def probe_page(page):
    """What headless Chromium finds on ``page`` (a copy of a site page with PROBE appended)."""
    with tempfile.TemporaryDirectory() as profile:
        proc = subprocess.run([CHROMIUM, *CHROMIUM_FLAGS, f"--user-data-dir={profile}",
                               "--virtual-time-budget=10000", "--dump-dom", page.as_uri()],
                              capture_output=True, text=True, timeout=120)
    m = re.search(r'<pre id="site-probe">(.*?)</pre>', proc.stdout, re.S)
    assert m, f"{page.name} did not load:\n{proc.stdout[:500]}\n{proc.stderr[-500:]}"
    text = m.group(1).replace("&lt;", "<").replace("&gt;", ">").replace("&quot;", '"')
    return json.loads(text.replace("&amp;", "&"))


def anchors(page, cache={}):
    if page not in cache:
        cache[page] = set(re.findall(r'\b(?:id|name)="([^"]+)"', page.read_text()))
    return cache[page]


def test_every_page_image_and_link(site, tmp_path):
    if CHROMIUM is None:
        pytest.skip("chromium not installed (make setup installs it)")
    copy = tmp_path / "html"
    shutil.copytree(site, copy)
    pages = sorted(copy.rglob("*.html"))
    names = {p.relative_to(copy).as_posix() for p in pages}
    # the landing page, every part of the site and every demo
    assert {"index.html", "getting_started.html", "demos/index.html", "models.html", "cli.html",
            "api.html", "report.html", "records.html"} <= names
    demos = {f"demos/{p.stem}.html" for p in (ROOT / "demos").glob("demo_*.py")}
    assert demos and demos <= names
    for page in pages:
        text = page.read_text()
        page.write_text(text.replace("</body>", PROBE + "</body>", 1) if "</body>" in text
                        else text + PROBE)
    images = links = 0
    problems = []
    for page in pages:
        name = page.relative_to(copy).as_posix()
        found = probe_page(page)
        images += found["images"]
        problems += [f"{name}: image does not load: {src}" for src in found["broken"]]
        problems += [f"{name}: loads from the network: {url}" for url in found["resources"]
                     if urlsplit(url).scheme in ("http", "https")]
        for href in found["links"]:
            url = urlsplit(href)
            if url.scheme != "file":
                continue  # external links are not followed
            links += 1
            target = Path(unquote(url.path))
            if target.is_dir():
                target = target / "index.html"
            if not target.is_file():
                problems.append(f"{name}: link to a missing file: {href}")
            elif url.fragment and target.suffix == ".html" \
                    and unquote(url.fragment) not in anchors(target):
                problems.append(f"{name}: link to a missing anchor: {href}")
    print(f"{len(pages)} pages, {images} images, {links} internal links checked")
    assert not problems, "\n".join(problems)
    assert images >= 2 * len(demos)  # every demo shows at least its figures


def test_broken_image_and_link_are_reported(site, tmp_path):
    """The check can fail: a missing image and a link to a missing anchor are found."""
    if CHROMIUM is None:
        pytest.skip("chromium not installed (make setup installs it)")
    page = tmp_path / "broken.html"
    shutil.copy2(site / "index.html", page)
    page.write_text(page.read_text().replace(
        "</body>", '<img src="missing.png"><a href="index.html#no-such-anchor">x</a>' + PROBE
        + "</body>", 1))
    found = probe_page(page)
    assert found["broken"] == [(tmp_path / "missing.png").as_uri()]
    assert (tmp_path / "index.html").as_uri() + "#no-such-anchor" in found["links"]


def test_generated_pages_follow_the_code(site):
    """The command-line page holds every subcommand's help; the API page every public name."""
    import damage_dolfinx
    cli = (site / "cli.html").read_text()
    for command in ("list", "run", "converge"):
        assert f"damage-dolfinx {command}" in cli
    assert "--checkpoint-seconds" in cli and "--ref-n" in cli
    api = (site / "api.html").read_text()
    for name in getattr(damage_dolfinx, "__all__", []):
        assert f'id="damage_dolfinx.{name}"' in api or f'id="module-damage_dolfinx.{name}"' in api \
            or re.search(rf'id="module-[\w.]*{name}"', api), name


def test_no_machine_paths(site):
    """The site names no folder of the machine it was built on (its pages are published)."""
    found = []
    for page in sorted(site.rglob("*.html")):
        text = re.sub(r"<[^>]+>", "", page.read_text())
        found += [f"{page.relative_to(site)}: {m.group(0)}"
                  for m in re.finditer(r"(?<![\w.])/(?:work|tmp|root|home)/[^\s'`\"<]*", text)]
    assert not found, f"{len(found)} machine paths:\n" + "\n".join(found[:20])


def test_report_copied_and_linked(tmp_path):
    """With a report in the results folder, the site links it, copied with its figures."""
    if CHROMIUM is None:
        pytest.skip("chromium not installed (make setup installs it)")
    results = tmp_path / "results"
    (results / "figures").mkdir(parents=True)
    (results / "unused.txt").write_text("not referenced by the report")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(2, 2))
    ax.plot([0, 1], [0, 1])
    fig.savefig(results / "figures" / "figure_2_1.png")
    plt.close(fig)
    (results / "REPORT.html").write_text(
        '<html><body><h1 id="top">Report</h1><img src="figures/figure_2_1.png">'
        '<a href="#top">top</a></body></html>')
    build_site(tmp_path / "site", results)
    html = tmp_path / "site" / "html"
    assert 'href="report/REPORT.html"' in (html / "report.html").read_text()
    assert (html / "report" / "figures" / "figure_2_1.png").is_file()
    assert not (html / "report" / "unused.txt").exists()  # only what the report uses
    page = html / "report" / "REPORT.html"
    page.write_text(page.read_text().replace("</body>", PROBE + "</body>"))
    found = probe_page(page)
    assert found["images"] == 1 and not found["broken"]
