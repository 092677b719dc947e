"""The package, its docs and the README refer only to files inside the repository.

The models page (docs/models.md) states each model's equations, scheme and the data the thesis
leaves open; docstrings and comments point there, never to a document outside the repository or
to a path of the machine the package was written on. The short codes of the defaults (``G3``)
stay only in the catalogue's ``assumptions`` data, which a run records in words and the report
translates.
"""
import ast
import io
import re
import subprocess
import tokenize
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: tracked paths that must speak for themselves
SCOPE = ("damage_dolfinx", "forms", "geometries", "README.md", "docs")

#: a document or folder outside the repository
OUTSIDE = re.compile(r"PROBLEMS\.md|\.\./shared|/work/|shared/thesis|thesis\.txt")

#: a bare gap code (G1 ... G43) or reading code (R1, R2) of the catalogue's assumptions
CODE = re.compile(r"\b[GR]\d{1,2}[a-z]?\b")


def tracked(*scope):
    try:
        out = subprocess.run(["git", "ls-files", "-z", "--", *scope], cwd=ROOT, check=True,
                             capture_output=True).stdout
        files = [ROOT / p for p in out.decode().split("\0") if p]
    except (OSError, subprocess.CalledProcessError):
        files = []
    if not files:  # not a git checkout: every file under the scope
        files = [p for s in scope for p in ([ROOT / s] if (ROOT / s).is_file()
                                            else (ROOT / s).rglob("*")) if p.is_file()]
    return [p for p in files if p.is_file()]


def text_of(path):
    try:
        return path.read_text(encoding="utf-8")
    except (UnicodeDecodeError, OSError):
        return None  # binary files (images) say nothing


def test_scope_is_not_empty():
    names = {p.relative_to(ROOT).as_posix() for p in tracked(*SCOPE)}
    assert "README.md" in names and "docs/models.md" in names
    assert any(n.startswith("damage_dolfinx/models/") for n in names)


def test_no_reference_outside_the_repository():
    hits = []
    for path in tracked(*SCOPE):
        text = text_of(path)
        if text is None:
            continue
        for number, line in enumerate(text.splitlines(), 1):
            if OUTSIDE.search(line):
                hits.append(f"{path.relative_to(ROOT)}:{number}: {line.strip()}")
    assert not hits, "references outside the repository:\n" + "\n".join(hits)


def docstrings_and_comments(source):
    """(line, text) of every docstring and comment of a Python source."""
    tree = ast.parse(source)
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(
                    getattr(body[0], "value", None), ast.Constant) and \
                    isinstance(body[0].value.value, str):
                yield body[0].lineno, body[0].value.value
    for token in tokenize.generate_tokens(io.StringIO(source).readline):
        if token.type == tokenize.COMMENT:
            yield token.start[0], token.string


@pytest.mark.parametrize("scope", ["damage_dolfinx", "forms", "geometries"])
def test_docstrings_and_comments_speak_in_words(scope):
    """No bare gap/reading code in a docstring or comment: the reader is pointed to the models
    page or told in words (the report, which translates the codes, lives outside the package)."""
    hits = []
    for path in tracked(scope):
        rel = path.relative_to(ROOT).as_posix()
        if path.suffix != ".py":
            continue
        for line, text in docstrings_and_comments(path.read_text(encoding="utf-8")):
            for match in CODE.finditer(text):
                hits.append(f"{rel}:{line}: {match.group(0)} in {text.strip()[:80]!r}")
    assert not hits, "codes in docstrings or comments:\n" + "\n".join(hits)


def test_models_page_has_a_section_per_model():
    from damage_dolfinx.models.registry import MODELS
    page = (ROOT / "docs" / "models.md").read_text(encoding="utf-8")
    assert not CODE.search(page), "the models page names a gap code"
    for model_id in MODELS:
        label = "(model-" + model_id.replace(".", "-") + ")="
        assert label in page, f"docs/models.md has no section {label}"
