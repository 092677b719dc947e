"""Package discovery (the rest of the metadata is in pyproject.toml).

Every package under ``damage_dolfinx/`` is found, and so is every package under the top-level
folders ``forms/`` and ``geometries/``, installed as ``damage_dolfinx.forms`` and
``damage_dolfinx.geometries`` (the mapping ``package-dir`` of pyproject.toml). pyproject.toml's
``packages.find`` cannot search a folder under another package name, hence this file: a new
module or subpackage is installed without editing any list (``tests/test_wheel.py`` builds the
wheel and compares its modules with the source tree).
"""
from setuptools import find_packages, setup

#: installed name -> source folder (the same mapping as pyproject.toml's package-dir)
MAPPED = {"damage_dolfinx.forms": "forms", "damage_dolfinx.geometries": "geometries"}

packages = find_packages(include=["damage_dolfinx", "damage_dolfinx.*"])
for name, folder in MAPPED.items():
    packages += [name] + [f"{name}.{sub}" for sub in find_packages(folder)]

setup(packages=sorted(set(packages)))
