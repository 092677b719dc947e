"""damage-dolfinx: continuum damage in solid mechanics with DOLFINx.

The public face (everything else is internal and may change):

* :class:`Problem`: one of the models on your mesh, with your boundary parts, loads, data,
  damage law and time grid; :data:`MODELS` lists the models, :func:`model_defaults` their data;
* :func:`run`, :func:`converge`, :func:`sweep`, :func:`gather`: run a problem into a run
  folder, study its convergence, run it over a grid of parameter values, gather a field on
  rank 0;
* :class:`DamageLaw` and the thesis laws :data:`THESIS_A`, :data:`THESIS_B`;
* :func:`read_mesh`, :func:`from_gmsh`: meshes from gmsh files or models;
* :class:`ModelParameters` (material, damage and model data), :class:`InputError`;
* the packages :mod:`damage_dolfinx.geometries` (mesh builders) and :mod:`damage_dolfinx.forms`
  (the weak forms in UFL).

Names are imported on first use, so ``import damage_dolfinx`` stays light.
"""
__version__ = "0.1.0"

__all__ = ["Problem", "MODELS", "model_defaults", "run", "converge", "sweep", "gather",
           "DamageLaw", "THESIS_A", "THESIS_B", "read_mesh", "from_gmsh", "ModelParameters",
           "InputError"]

_WHERE = {"Problem": "problem", "run": "workflow", "converge": "workflow",
          "sweep": "workflow", "gather": "workflow", "DamageLaw": "laws", "THESIS_A": "laws",
          "THESIS_B": "laws", "read_mesh": "meshes", "from_gmsh": "meshes",
          "ModelParameters": "parameters", "InputError": "parameters"}


def __getattr__(name):
    import importlib
    if name in _WHERE:
        return getattr(importlib.import_module(f"damage_dolfinx.{_WHERE[name]}"), name)
    if name == "MODELS":
        from damage_dolfinx.models.registry import MODELS
        return {key: m.title for key, m in MODELS.items()}
    if name == "model_defaults":
        from damage_dolfinx.models.registry import default_parameters
        return default_parameters
    raise AttributeError(f"module 'damage_dolfinx' has no attribute {name!r}")


def __dir__():
    return sorted(list(globals()) + __all__)
