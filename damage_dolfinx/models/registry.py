"""The models by id, derived from the model classes (each declares its id, title, contact roles,
default data, checks and stability limit: models/base.py, :class:`~damage_dolfinx.Model`).

The default data of a model are a generic starting point, not necessarily a thesis example's (the
catalogue holds those); a problem replaces any of them. docs/models.md lists them per model.
A model of your own (a :class:`~damage_dolfinx.Model` subclass) is passed to
:class:`~damage_dolfinx.Problem` as it is; :func:`register` adds it to the registry by its id.
"""
from __future__ import annotations

import importlib

from damage_dolfinx.core.parameters import InputError, ModelParameters
from damage_dolfinx.core.tags import CONTACT_ROLES  # what Gamma_C may mean
from damage_dolfinx.core.tags import GAMMA_C as CONTACT, GAMMA_D as CLAMPED, GAMMA_N as TRACTION  # noqa: F401

ROLES = ("clamped", "traction") + CONTACT_ROLES

#: the modules under damage_dolfinx/models/ holding the catalogue's models, in catalogue order
MODULES = ("elastic_2_1", "bridge_2_1", "kelvin_voigt_2_2", "memory_2_3", "viscoplastic_2_4",
           "viscoplastic_compliance_2_4",
           "dynamic_3_1", "dynamic_tresca_3_2", "fully_damageable_3_3")

_registered: dict = {}


def _models() -> dict:
    """id -> model class, every Model subclass that a module of MODULES defines with an id."""
    if not _registered:
        from damage_dolfinx.models.base import Model
        for name in MODULES:
            module = importlib.import_module(f"{__package__}.{name}")
            for obj in vars(module).values():
                if (isinstance(obj, type) and issubclass(obj, Model) and obj.id
                        and obj.__module__ == module.__name__):
                    _registered[obj.id] = obj
    return _registered


def __getattr__(name):
    if name == "MODELS":  # built on first use (importing the models imports DOLFINx)
        return _models()
    raise AttributeError(name)


def register(cls):
    """Add a model class of your own to the registry (by its ``id``); returns it (a decorator)."""
    from damage_dolfinx.models.base import Model
    if not (isinstance(cls, type) and issubclass(cls, Model) and isinstance(cls.id, str)
            and cls.id):
        raise InputError("a model is a damage_dolfinx.Model subclass with an id")
    if _models().get(cls.id, cls) is not cls:
        raise InputError(f"model id {cls.id!r} is taken by {_models()[cls.id].__name__}")
    _registered[cls.id] = cls
    return cls


def model(which):
    """The model class of ``which``: an id (a key of ``damage_dolfinx.MODELS``), or a model
    class itself."""
    from damage_dolfinx.models.base import Model
    if isinstance(which, type) and issubclass(which, Model):
        if not which.id:
            raise InputError(f"model class {which.__name__} declares no id")
        return which
    models = _models()
    if which not in models:
        raise InputError(f"unknown model {which!r}; known: {', '.join(models)}")
    return models[which]


def default_parameters(which) -> ModelParameters:
    """Default data of a model (a generic starting point; docs/models.md, the model's section)."""
    return model(which).defaults()


def validate(which, params: ModelParameters) -> ModelParameters:
    """The generic checks of ``params`` and the model's own (``Model.check``)."""
    cls = model(which)
    params.validate(cls.data_rules())
    return cls.check(params)


def quasistatic_k_max(which, params: ModelParameters) -> float:
    """k_max of a quasistatic scheme with an explicit term (inf: none): ``Model.k_max``."""
    return model(which).k_max(params)
