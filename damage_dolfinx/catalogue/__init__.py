"""Thesis examples, one module per section; each defines examples() -> [Example]. Importing
this package makes the catalogue's ids known to the run machinery (runtime/cases.py)."""
from damage_dolfinx.catalogue import examples
from damage_dolfinx.runtime import cases

cases.register(examples.get)
