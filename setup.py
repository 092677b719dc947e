"""Package discovery (the metadata is in pyproject.toml): every folder of damage_dolfinx/ with an
__init__.py, and the top-level forms/ and geometries/ (and any subpackage of theirs) installed
as damage_dolfinx.forms and damage_dolfinx.geometries (pyproject.toml's package-dir)."""
from setuptools import find_packages, setup

MAPPED = {"forms": "damage_dolfinx.forms", "geometries": "damage_dolfinx.geometries"}

packages = find_packages(include=["damage_dolfinx", "damage_dolfinx.*"])
for folder, name in MAPPED.items():
    packages += [name] + [f"{name}.{sub}" for sub in find_packages(where=folder)]

setup(packages=packages, package_data={"damage_dolfinx": ["py.typed"]})
