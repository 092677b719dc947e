"""Sphinx configuration of the damage-dolfinx documentation (``make docs``).

The pages below are generated here at every build, from the code itself, into ``_generated/``
(not kept in git) and included by their page:

- ``cli.md``: ``damage-dolfinx --help`` and the help of every subcommand, from the argparse
  parser of the ``damage_dolfinx.cli`` package;
- ``api.md``: one autodoc entry per name in ``damage_dolfinx.__all__`` (functions, classes,
  modules, data), so a name added to ``__all__`` is documented without touching the docs;
- ``records.md``: ``benchmarks/README.md`` with its headings one level down;
- ``catalogue.md``: every example of the catalogue, from the catalogue itself: its model, mesh,
  default n or h, k, T, the thesis figures and study it reproduces, the text of
  ``damage-dolfinx show ID``;
- ``report.md``: a link to the thesis reproduction report when ``make report`` has written it
  (``$DAMAGE_DOLFINX_RESULTS/REPORT.html``, default ``results/``); the report and the files it
  refers to are copied into the site.

The demos (``demos/*.py``) are executed by sphinx-gallery; each writes its run folder under
``$DAMAGE_DOLFINX_DEMO_OUT`` (set here to ``<build>/demo-output`` unless already set).
"""
import argparse
import importlib
import inspect
import os
import pprint
import re
import shutil
import sys
import textwrap
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))
os.environ.setdefault("MPLBACKEND", "Agg")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import damage_dolfinx  # noqa: E402

project = "damage-dolfinx"
author = "damage-dolfinx contributors"
copyright = "damage-dolfinx contributors"
release = version = damage_dolfinx.__version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "sphinx_gallery.gen_gallery",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "_generated", "Thumbs.db", ".DS_Store",
                    "demos/*.md5", "demos/*.py", "demos/*.ipynb"]
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
# Sphinx >= 7.3 (Debian 13 and later) warns that sphinx_gallery_conf (it holds a sort key class)
# cannot be cached between builds: the build is always complete anyway
suppress_warnings = ["config.cache"]
myst_heading_anchors = 3

autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_typehints_description_target = "documented"  # no lists of undocumented parameters
# the source pages link back to where an object is documented under its own module; a name
# re-exported at the top level or by damage_dolfinx.models.blocks gets no back-link (viewcode keeps one
# documenting module per source module, and would link the others to missing anchors)
viewcode_follow_imported_members = False
autodoc_default_options = {"members": True, "undoc-members": False, "show-inheritance": True}
napoleon_google_docstring = True
napoleon_numpy_docstring = True
napoleon_use_ivar = True  # "Attributes:" as fields: a dataclass's fields are not listed twice

html_theme = "furo"
html_title = f"damage-dolfinx {release}"
html_static_path = []
html_show_sourcelink = False
html_copy_source = False
html_last_updated_fmt = None

GENERATED = HERE / "_generated"
GENERATED.mkdir(exist_ok=True)


def _write_if_changed(path, text):
    """Rewrite a generated page only when its text changes (keeps Sphinx's cache valid)."""
    if not path.exists() or path.read_text() != text:
        path.write_text(text)


# --- MathJax from the Debian package (libjs-mathjax), so the site renders its equations
# offline; without it Sphinx's default (a CDN) is used.
MATHJAX = Path("/usr/share/javascript/mathjax")
MATHJAX_PARTS = ("MathJax.js", "config/TeX-AMS_CHTML.js", "extensions", "jax/input/TeX",
                 "jax/element", "jax/output/CommonHTML", "fonts/HTML-CSS/TeX/woff")
if (MATHJAX / "MathJax.js").is_file():
    _static = GENERATED / "static"
    for part in MATHJAX_PARTS:
        src, dst = MATHJAX / part, _static / "mathjax" / part
        if dst.exists():
            continue
        dst.parent.mkdir(parents=True, exist_ok=True)
        (shutil.copytree if src.is_dir() else shutil.copy2)(src, dst)
    html_static_path = [str(_static)]
    mathjax_path = "mathjax/MathJax.js?config=TeX-AMS_CHTML"
    myst_update_mathjax = False  # MyST's classes would hide its pages' math from MathJax 2


# --- sphinx-gallery: the demos -------------------------------------------------------------
_OUT = Path(os.environ.get("DAMAGE_DOLFINX_DOCS_BUILD", ROOT / "build" / "docs"))
os.environ.setdefault("DAMAGE_DOLFINX_DEMO_OUT", str(_OUT / "demo-output"))

from sphinx_gallery.sorting import FileNameSortKey  # noqa: E402

sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "demos"),
    "gallery_dirs": "demos",
    "filename_pattern": r"/demo_",      # execute every demo
    "ignore_pattern": r"(__init__|conftest|test_)",
    "within_subsection_order": FileNameSortKey,
    "download_all_examples": False,
    "remove_config_comments": True,
    "min_reported_time": 0,
    "capture_repr": (),
    "image_scrapers": ("matplotlib",),
    "matplotlib_animations": False,
    "reset_modules": ("matplotlib",),
    "line_numbers": False,
    "reference_url": {"damage_dolfinx": None},  # names in the demos' code link to the API page
}


# --- command-line reference ----------------------------------------------------------------
def _cli_page():
    from damage_dolfinx import cli
    os.environ["COLUMNS"] = "80"  # argparse wraps at the terminal width: the width of the page
    parser = cli._parser()
    subs = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    lines = ["## `damage-dolfinx`", "", "```text", parser.format_help().rstrip(), "```", ""]
    for name, sub in subs.choices.items():
        lines += [f"## `damage-dolfinx {name}`", "", "```text", sub.format_help().rstrip(),
                  "```", ""]
    return "\n".join(lines)


# --- API reference -------------------------------------------------------------------------
def _api_page():
    names = list(getattr(damage_dolfinx, "__all__", []))
    if not names:
        return ("The package does not declare its public names yet "
                "(`damage_dolfinx.__all__` is empty).\n")
    groups = {"Functions": [], "Classes": [], "Modules": [], "Data": []}
    for name in names:
        obj = getattr(damage_dolfinx, name)
        if inspect.ismodule(obj):
            kind, directive = "Modules", f".. automodule:: {obj.__name__}\n   :members:"
            shared = sorted(n for n in names if n != name and hasattr(obj, n))
            if shared:  # documented once, at the top level
                directive += f"\n   :exclude-members: {', '.join(shared)}"
        elif inspect.isclass(obj):
            kind, directive = "Classes", f".. autoclass:: damage_dolfinx.{name}\n   :members:"
            # the members of a base of the package's own that is no public name (Model's
            # Reporting) are documented with the public class
            if any(b.__module__.startswith("damage_dolfinx.") and b.__name__ not in names
                   for b in obj.__mro__[1:]):
                directive += "\n   :inherited-members:"
        elif inspect.isroutine(obj):
            kind, directive = "Functions", f".. autofunction:: damage_dolfinx.{name}"
        else:
            kind, directive = "Data", f".. autodata:: damage_dolfinx.{name}\n   :no-value:"
            value = pprint.pformat(obj, width=88, sort_dicts=False)
            if isinstance(obj, (dict, list, tuple, str, int, float)) and len(value) < 3000:
                directive += "\n\n   .. code-block:: python\n\n" + textwrap.indent(value, "      ")
        # a module gets a heading; functions and classes are listed by the page's contents
        heading = f"### `{obj.__name__}`\n\n" if kind == "Modules" else ""
        groups[kind].append(f"{heading}```{{eval-rst}}\n{directive}\n```\n")
    lines = ["```{eval-rst}", ".. automodule:: damage_dolfinx", "   :no-members:", "```", ""]
    for kind, entries in groups.items():
        if entries:
            lines += [f"## {kind}", "", *entries]
    return "\n".join(lines)


# --- the catalogue of examples ------------------------------------------------------------
def _thesis_figure(filename):
    """'figure_2_12_left.png' -> 'Fig. 2.12 (left)', 'figure_2_24_25.png' -> 'Figs 2.24-2.25';
    a figure of the package's own (fields_final.png, ...) -> None."""
    m = re.fullmatch(r"figure_(\d)_(\d+)(?:_(\d+))?(?:_(left|right))?\.png", filename)
    if not m:
        return None
    chapter, first, second, side = m.groups()
    text = (f"Figs {chapter}.{first}-{chapter}.{second}" if second
            else f"Fig. {chapter}.{first}")
    return text + (f" ({side})" if side else "")


def _cell(text):
    return str(text).replace("|", "\\|").replace("\n", " ")


def _catalogue_page():
    """Every example of the catalogue (``damage-dolfinx list``), from the catalogue itself: a
    table of its data, then each example with what it reproduces and the text of
    ``damage-dolfinx show ID``."""
    from damage_dolfinx.catalogue.examples import catalogue
    from damage_dolfinx.cli.show import show
    from damage_dolfinx.models.registry import model
    examples = list(catalogue().values())
    lines = ["| id | thesis | model | mesh | default n / h | k | T | reproduces |",
             "|---|---|---|---|---|---|---|---|"]
    details = []
    for ex in examples:
        info = model(ex.model_id)
        where = f"§{ex.section}" if ex.dim == 2 else f"beyond the thesis (§{ex.section} in 3-D)"
        mesh = (f"gmsh, {ex.dim}-D" if ex.h is not None else f"structured family, {ex.dim}-D")
        size = f"h = {ex.h:g}" if ex.h is not None else f"n = {ex.n}"
        figures = [f for f in ex.figures if _thesis_figure(f.filename)]
        what = [_thesis_figure(f.filename) for f in figures]
        if ex.convergence:
            what.append("convergence study")
        if not what:
            what = ["the package's own figures"]
        anchor = "ex-" + re.sub(r"[^a-z0-9]+", "-", ex.id.lower())
        lines.append(f"| {{ref}}`{ex.id} <{anchor}>` | {where} | {ex.model_id}: {_cell(info.title)} | "
                     f"{mesh} | {size} | {ex.k:.4g} | {ex.T:g} | {', '.join(what)} |")
        details += [f"({anchor})=", f"### `{ex.id}`: {_cell(ex.title)}", ""]
        for f in ex.figures:
            number = _thesis_figure(f.filename)
            details.append(f"- `{f.filename}`: {_cell(f.title)}"
                           + (f" (thesis {number})" if number else ""))
        if ex.convergence:
            c = ex.convergence
            details.append(f"- `damage-dolfinx converge {ex.id}`: the thesis convergence study, "
                           f"reference n = {c.get('ref_n')}, k = {c.get('ref_k'):g}; levels "
                           f"n = {', '.join(map(str, c.get('n', [])))}, "
                           f"k = {', '.join(f'{k:g}' for k in c.get('k', []))}")
        details += ["", "```text", f"$ damage-dolfinx show {ex.id}", show(ex.id, {}).rstrip(),
                    "```", ""]
    return "\n".join(lines + ["", "## Every example", ""] + details)


# --- the thesis reproduction report --------------------------------------------------------
def _report_page(app):
    results = Path(os.environ.get("DAMAGE_DOLFINX_RESULTS", ROOT / "results"))
    page = results / "REPORT.html"
    if not page.is_file():
        return ("The report has not been built in this checkout. Run `make report` (after "
                "`make figures` and `make convergence`), then `make docs` again: the report "
                "is then copied into this site and linked here.\n")
    target = Path(app.outdir) / "report"
    if target.exists():
        shutil.rmtree(target)
    target.mkdir(parents=True)
    html = page.read_text()
    shutil.copy2(page, target / "REPORT.html")
    for ref in set(re.findall(r'(?:src|href)="([^"#:]+)"', html)):
        src = (results / ref).resolve()
        if src.is_file() and results.resolve() in src.parents:
            (target / ref).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, target / ref)
    return ('The report of this checkout, built by `make report`: '
            '<a href="report/REPORT.html">open the thesis reproduction report</a>.\n')


# --- measured records ----------------------------------------------------------------------
def _records_page():
    """benchmarks/README.md as it is, every heading one level down (under the page's title)."""
    lines, fenced = [], False
    for line in (ROOT / "benchmarks" / "README.md").read_text().splitlines():
        if line.lstrip().startswith(("```", "~~~")):
            fenced = not fenced
        if not fenced and re.match(r"#{1,5} ", line):
            line = "#" + line
        lines.append(line)
    return "\n".join(lines) + "\n"


def _generate(app):
    _write_if_changed(GENERATED / "cli.md", _cli_page())
    _write_if_changed(GENERATED / "api.md", _api_page())
    _write_if_changed(GENERATED / "report.md", _report_page(app))
    _write_if_changed(GENERATED / "records.md", _records_page())
    _write_if_changed(GENERATED / "catalogue.md", _catalogue_page())


def _attribute_comment(name, obj):
    """The ``#:`` comment of ``name`` in the package module that defines ``obj``, if any."""
    from sphinx.pycode import ModuleAnalyzer
    for modname, module in sorted(sys.modules.items()):
        if modname.startswith("damage_dolfinx.") and getattr(module, name, None) is obj:
            try:
                docs = ModuleAnalyzer.for_module(modname).find_attr_docs()
            except Exception:  # noqa: BLE001 - a module without source: no comment
                continue
            if ("", name) in docs:
                return [line for line in docs[("", name)]]
    return []


def _data_docstring(app, what, name, obj, options, lines):
    """A public data object (a dict, a law instance) has no docstring of its own: autodoc
    would show its type's (dict's, DamageLaw's). Use the ``#:`` comment where it is defined."""
    if what != "data":
        return
    type_doc = inspect.getdoc(type(obj)) or ""
    if not lines or (type_doc and type_doc.splitlines()[0].strip() == lines[0].strip()):
        lines[:] = _attribute_comment(name.rsplit(".", 1)[-1], obj)


def _offline_execution_times(app, docname, source):
    """sphinx-gallery >= 0.14 (Debian 13 and later) styles its execution-time tables with
    scripts and sheets from CDNs; the site loads nothing from the network, so those lines go (the
    table stays, unstyled)."""
    if docname.endswith("sg_execution_times"):
        source[0] = "\n".join(line for line in source[0].splitlines()
                              if not re.search(r"<(script|link)[^>]+https?://", line))


def setup(app):
    app.connect("builder-inited", _generate)
    app.connect("source-read", _offline_execution_times)
    app.connect("autodoc-process-docstring", _data_docstring)
