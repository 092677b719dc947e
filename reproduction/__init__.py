"""The thesis reproduction: figure and table runs, their checks, and the report document.

This package is not part of the installed library: it lives at the top of the checkout, next to
``benchmarks/`` (whose committed records it reads) and ``damage_dolfinx/`` (the library it runs).
Import it from the checkout: the tests put the checkout on ``sys.path`` (pytest's ``pythonpath``
setting in pyproject.toml), and the scripts in ``benchmarks/reproduction/`` do so through
``benchmarks/common.py``.
"""
from pathlib import Path

#: the checkout this package sits in (the folder holding ``reproduction/`` and ``benchmarks/``)
CHECKOUT = Path(__file__).resolve().parent.parent
