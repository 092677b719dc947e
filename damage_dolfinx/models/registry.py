"""The models by id: their time stepper, the contact role of their Gamma_C, and default data.

The default data of a model are a generic starting point, not necessarily a thesis example's (the
catalogue holds those); a problem replaces any of them. docs/models.md lists them per model.
"""
from __future__ import annotations

import dataclasses
import importlib
import math
from dataclasses import dataclass

from damage_dolfinx.parameters import InputError, ModelParameters

#: boundary roles and the internal facet tag each one becomes (the steppers read these tags)
CLAMPED, TRACTION, CONTACT = 1, 2, 3
#: contact roles: what Gamma_C means in each model
CONTACT_ROLES = ("bilateral", "tresca", "coulomb", "normal_compliance")
ROLES = ("clamped", "traction") + CONTACT_ROLES

#: Uzawa step and Bermudez-Moreno parameter of the friction baselines (friction/baselines.py)
RHO_UZAWA, OMEGA_PD = 1.0, 100.0

_FRICTION = {"eps_reg": 1e-9, "friction_solver": "newton", "rho_uzawa": RHO_UZAWA,
             "omega_pd": OMEGA_PD, "friction_tol": 1e-6}


@dataclass(frozen=True)
class ModelInfo:
    id: str
    title: str
    stepper: str            # "module:Class" under damage_dolfinx.models
    contact: tuple          # the contact roles its Gamma_C may play
    explicit: str           # what limits k ("" when nothing does)

    def stepper_class(self):
        module, name = self.stepper.split(":")
        return getattr(importlib.import_module(f"damage_dolfinx.models.{module}"), name)


MODELS = {m.id: m for m in [
    ModelInfo("2.1", "quasistatic elastic body with damage", "elastic_2_1:ElasticDamage",
              ("bilateral",), ""),
    ModelInfo("2.1-collapse", "quasistatic elastic masonry under a growing load, to collapse",
              "bridge_2_1:BridgeDamage", (), ""),
    ModelInfo("2.2", "quasistatic Kelvin-Voigt body, bilateral contact with Tresca friction",
              "kelvin_voigt_2_2:KelvinVoigtTresca", ("tresca",),
              "explicit elastic term: k <= 2/m_visc"),
    ModelInfo("2.3", "quasistatic viscoelastic body with long memory, normal compliance",
              "memory_2_3:ViscoelasticMemoryContact", ("normal_compliance",), ""),
    ModelInfo("2.4", "quasistatic elastic-viscoplastic body, Tresca (P1) or simplified Coulomb "
              "(P2) friction", "viscoplastic_2_4:ElastoViscoplasticFriction",
              ("tresca", "coulomb"), "explicit viscoplastic term: k <= 2/(1 - zeta*)"),
    ModelInfo("3.1", "dynamic Kelvin-Voigt body, normal compliance",
              "dynamic_3_1:DynamicKelvinVoigt", ("normal_compliance",),
              "explicit elastic and contact forces (eigenvalue estimate)"),
    ModelInfo("3.2", "dynamic Kelvin-Voigt body, bilateral contact with Tresca friction",
              "dynamic_tresca_3_2:DynamicTresca", ("tresca",),
              "explicit elastic force (eigenvalue estimate)"),
    ModelInfo("3.3", "dynamic fully damageable body, normal compliance",
              "fully_damageable_3_3:FullyDamageableContact", ("normal_compliance",),
              "explicit elastic and contact forces (eigenvalue estimate)"),
]}


def model(model_id: str) -> ModelInfo:
    if model_id not in MODELS:
        raise InputError(f"unknown model {model_id!r}; known: {', '.join(MODELS)}")
    return MODELS[model_id]


def default_parameters(model_id: str) -> ModelParameters:
    """Default data of a model (a generic starting point; docs/models.md, the model's section)."""
    damage_A = dict(kappa=1e-2, zeta_star=0.01, q_star=1000.0, variant="A", lam_D=0.1,
                    lam_u=1000.0, lam_w=0.0, L_trunc=1000.0, stop_at_zeta_star=False)
    if model(model_id).id == "2.1":
        return ModelParameters(E=1e4, nu=0.33, kappa=1.0, zeta_star=0.01, q_star=1000.0,
                               variant="B", lam_D=0.1, lam_w=0.0, lam_u_plus=1000.0,
                               lam_u_minus=100.0, stop_at_zeta_star=True)
    if model_id == "2.1-collapse":
        from damage_dolfinx.models.bridge_2_1 import BRIDGE_DEFAULTS
        return dataclasses.replace(default_parameters("2.1"), stop_at_zeta_star=False,
                                   extra=dict(BRIDGE_DEFAULTS))
    if model_id == "2.2":
        return ModelParameters(E=5000.0, nu=0.3, **damage_A,
                               extra={"m_visc": 100.0, "g_fric": 5.0, **_FRICTION})
    if model_id == "2.3":
        return ModelParameters(E=1e4, nu=0.3, **dict(damage_A, lam_D=1e-2, lam_u=10.0),
                               extra={"c_nu": 1e10, "gap": 0.0, "memory_kernel": "constant",
                                      "memory_amplitude": 1.0, "memory_rate": 1.0,
                                      "memory_mode": "auto"})
    if model_id == "2.4":
        return ModelParameters(E=1000.0, nu=0.3, **damage_A, extra={
            "friction_law": "tresca", "g_fric": 5.0, "mu_f": 0.05, "S_n": 10.0,
            "coulomb_normal": "free", "viscoplastic_sign": 1.0, "stress_in_error": "yes",
            **_FRICTION})
    if model_id == "3.1":
        return ModelParameters(E=1e4, nu=0.3, **dict(damage_A, kappa=1.0, q_star=1.0),
                               extra={"rho": 1.0, "m_visc": 10.0, "c_nu": 1e4, "gap": 0.0,
                                      "damage_active": True, "stability_check": "error",
                                      "error_norm": "velocity"})
    if model_id == "3.2":
        return ModelParameters(E=1e4, nu=0.3, **dict(damage_A, kappa=1.0, lam_D=0.0),
                               extra={"rho": 1.0, "m_visc": 100.0, "g_fric": 5.0,
                                      "stability_check": "error", **_FRICTION})
    return ModelParameters(E=1e4, nu=0.3, **dict(damage_A, kappa=1.0, lam_D=0.0),
                           extra={"rho": 1.0, "m_visc": 100.0, "c_nu": 1e4, "gap": 0.0,
                                  "damage_active": True, "stability_check": "error",
                                  "elastic_term": "explicit"})


def validate(model_id: str, params: ModelParameters) -> ModelParameters:
    """The model's own checks of its data in ``params.extra`` (after ``params.validate()``)."""
    params.validate()
    if model_id == "2.1-collapse":
        from damage_dolfinx.models.bridge_2_1 import check_bridge_parameters
        check_bridge_parameters(params.extra)
    return params


def quasistatic_k_max(model_id: str, params: ModelParameters) -> float:
    """k_max of the quasistatic schemes with an explicit term (inf: none).

    * 2.2: the velocity step A eps(v_n) = -zeta Phi_L(B eps(u_{n-1})) + ..., A = B/m_visc with
      the same boundary conditions, gives u_n = (1 - k m_visc zeta) u_{n-1} mode by mode:
      stable iff k m_visc zeta <= 2, so k_max = 2/m_visc (zeta <= 1).
    * 2.4: the explicit viscoplastic rate Ghat = (1 - zeta) Phi_L(sigma) (2.184) multiplies the
      self-equilibrated stress by 1 + k sign (1 - zeta) per step: with the relaxing sign this
      is stable iff k (1 - zeta) <= 2, so k_max = 2/(1 - zeta*); with the thesis sign the
      continuous stress itself grows (by e^{k(1 - zeta)} per step) and the same bound keeps the
      scheme's growth factor below 3.
    """
    if model_id == "2.2":
        return 2.0 / float(params.extra["m_visc"])
    if model_id == "2.4":
        return 2.0 / (1.0 - params.zeta_star)
    return math.inf
