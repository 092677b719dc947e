"""damage-dolfinx: continuum damage in solid mechanics with DOLFINx.

The public face (everything else is internal and may change):

* :class:`Problem`: one of the models on your mesh, with your boundary parts, loads, data,
  damage law and time grid; :data:`MODELS` lists the models, :func:`model_defaults` their data;
* :func:`run`, :func:`converge`, :func:`sweep`, :func:`gather`: run a problem into a run
  folder, study its convergence, run it over a grid of parameter values, gather a field on
  rank 0; :func:`steps`: the same run step by step in your script (the live Functions, your
  monitors, a stop on your criterion);
* :class:`Model` (the base of every model: a model of your own derives from it, from the
  building blocks of :mod:`damage_dolfinx.blocks`), :class:`SubStep`
  (a model is built from a :class:`Problem` whose mesh is built), :func:`register_model`,
  :func:`model_class` (a model's class by id), :func:`register_example` (a Problem runnable
  by its id, e.g. from the command line through a plugin);
* :class:`DamageLaw` and the thesis laws :data:`THESIS_A`, :data:`THESIS_B`;
* :func:`petsc_options_from_argv`: the PETSc options of your script's command line
  (``python my_run.py -mech_ksp_type cg``), for ``run(..., petsc_options=...)``;
* :func:`read_run`: a run folder back into a script (summary, history arrays, fields at any
  stored time);
* :func:`read_mesh`, :func:`from_gmsh`: meshes from gmsh files or models;
* :class:`ModelParameters` (material, damage and model data);
* the exceptions :class:`InputError` (bad input, refused before any work),
  :class:`ConvergenceError` (a solver failed), :class:`OutputError` (an output could not be
  written), :class:`RunInterrupted` (stopped by a signal, with a checkpoint): damage_dolfinx.errors;
* the packages :mod:`damage_dolfinx.geometries` (mesh builders) and :mod:`damage_dolfinx.forms`
  (the weak forms in UFL).

Names are imported on first use, so ``import damage_dolfinx`` stays light.
"""
__version__ = "0.1.0"

# the user's root logger is theirs: FFCx's configuration of it at import is undone, whichever
# of the package's modules imports DOLFINx first (_logs.py; no DOLFINx import here)
from damage_dolfinx._logs import keep_root_at_ffcx_import as _keep  # noqa: E402

_keep()
del _keep

__all__ = ["Problem", "MODELS", "model_defaults", "run", "steps", "converge", "sweep", "gather",
           "Model", "SubStep", "register_model", "model_class", "blocks",
           "DamageLaw", "THESIS_A", "THESIS_B", "read_mesh", "from_gmsh", "ModelParameters",
           "InputError", "ConvergenceError", "OutputError", "RunInterrupted", "read_run",
           "register_example", "petsc_options_from_argv"]

_WHERE = {"Problem": "problem", "run": "workflow", "steps": "workflow", "Model": "models.base",
          "SubStep": "models.base", "converge": "workflow",
          "sweep": "workflow", "gather": "workflow", "DamageLaw": "laws", "THESIS_A": "laws",
          "THESIS_B": "laws", "read_mesh": "meshes", "from_gmsh": "meshes",
          "ModelParameters": "parameters", "InputError": "parameters", "read_run": "results",
          "ConvergenceError": "numerics.solvers", "OutputError": "runtime.atomic",
          "RunInterrupted": "runtime.signals", "register_example": "runtime.cases",
          "petsc_options_from_argv": "cli.petsc_options"}


def __getattr__(name):
    import importlib
    if name in _WHERE:
        return getattr(importlib.import_module(f"damage_dolfinx.{_WHERE[name]}"), name)
    if name == "MODELS":
        from damage_dolfinx.models.registry import MODELS
        return {key: m.title for key, m in MODELS.items()}
    if name == "blocks":  # the building blocks of the models (a module)
        return importlib.import_module("damage_dolfinx.blocks")
    if name == "register_model":
        from damage_dolfinx.models.registry import register
        return register
    if name == "model_class":
        from damage_dolfinx.models.registry import model
        return model
    if name == "model_defaults":
        from damage_dolfinx.models.registry import default_parameters
        return default_parameters
    raise AttributeError(f"module 'damage_dolfinx' has no attribute {name!r}")


def __dir__():
    return sorted(list(globals()) + __all__)
