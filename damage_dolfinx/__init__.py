"""damage-dolfinx: continuum damage in solid mechanics with DOLFINx.

The public face (everything else is internal and may change):

* :class:`Problem`: one of the models on your mesh, with your boundary parts, loads, data,
  damage law and time grid; :data:`MODELS` lists the models, :func:`model_defaults` their data;
* :func:`run`, :func:`converge`, :func:`sweep`, :func:`gather`: run a problem into a run
  folder, study its convergence, run it over a grid of parameter values, gather a field on
  rank 0; :func:`steps`: the same run step by step in your script (the live Functions, your
  monitors, a stop on your criterion);
* :class:`Model` (the base of every model: a model of your own derives from it, from the
  building blocks of :mod:`damage_dolfinx.models.blocks`), :class:`SubStep`
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
  written), :class:`RunInterrupted` (stopped by a signal, with a checkpoint): damage_dolfinx.core.errors;
* the packages :mod:`damage_dolfinx.geometries` (mesh builders) and :mod:`damage_dolfinx.forms`
  (the weak forms in UFL).

Names are imported on first use, so ``import damage_dolfinx`` stays light.
"""
from damage_dolfinx.core.version import __version__  # noqa: F401

# the user's root logger is theirs: FFCx's configuration of it at import is undone, whichever
# of the package's modules imports DOLFINx first (core/logs.py; no DOLFINx import here)
from damage_dolfinx.core.logs import keep_root_at_ffcx_import as _keep  # noqa: E402

_keep()
del _keep

__all__ = ["Problem", "MODELS", "model_defaults", "run", "steps", "converge", "sweep", "gather",
           "Model", "SubStep", "register_model", "model_class", "blocks",
           "DamageLaw", "THESIS_A", "THESIS_B", "read_mesh", "from_gmsh", "ModelParameters",
           "InputError", "ConvergenceError", "OutputError", "RunInterrupted", "read_run",
           "check_model", "register_example", "petsc_options_from_argv"]

_WHERE = {"Problem": "problem.problem", "run": "api.workflow", "steps": "api.workflow",
          "Model": "models.base", "SubStep": "models.base", "converge": "api.workflow",
          "sweep": "api.workflow", "gather": "api.workflow", "DamageLaw": "models.laws",
          "THESIS_A": "models.laws", "THESIS_B": "models.laws", "read_mesh": "problem.meshes",
          "from_gmsh": "problem.meshes", "ModelParameters": "core.parameters",
          "InputError": "core.errors", "read_run": "api.results",
          "ConvergenceError": "core.errors", "OutputError": "core.errors",
          "RunInterrupted": "core.errors", "check_model": "api.model_check",
          "register_example": "runtime.cases",
          "petsc_options_from_argv": "problem.petsc_options"}


def __getattr__(name):
    import importlib
    if name in _WHERE:
        return getattr(importlib.import_module(f"damage_dolfinx.{_WHERE[name]}"), name)
    if name == "MODELS":
        from damage_dolfinx.models.registry import MODELS
        return {key: m.title for key, m in MODELS.items()}
    if name == "blocks":  # the building blocks of the models (a module)
        return importlib.import_module("damage_dolfinx.models.blocks")
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



#: modules of earlier releases, by their old names: importing one still works, with a warning
_MOVED = {"blocks": "models.blocks", "errors": "core.errors", "laws": "models.laws",
          "parameters": "core.parameters", "results": "api.results",
          "workflow": "api.workflow", "meshes": "problem.meshes"}


class _MovedModules:
    """Import finder of the old module names (``damage_dolfinx.blocks`` ...): the module under
    its new name, with a DeprecationWarning naming it."""

    @staticmethod
    def find_spec(fullname, path=None, target=None):
        prefix, _, rest = fullname.partition(".")
        if prefix != "damage_dolfinx" or rest not in _MOVED:
            return None
        import importlib.util
        return importlib.util.spec_from_loader(fullname, _MovedModules)

    @staticmethod
    def create_module(spec):
        import importlib
        import warnings
        new = f"damage_dolfinx.{_MOVED[spec.name.partition('.')[2]]}"
        warnings.warn(f"{spec.name} is now {new}", DeprecationWarning, stacklevel=3)
        return importlib.import_module(new)

    @staticmethod
    def exec_module(module):
        pass


def _install_moved_modules():
    import sys
    if not any(finder is _MovedModules for finder in sys.meta_path):
        sys.meta_path.append(_MovedModules)


_install_moved_modules()

def __dir__():
    return sorted(list(globals()) + __all__)
