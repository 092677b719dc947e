"""Model and time parameters with validation (names: docs/models.md, "Common notation").

Invalid input is refused here, before any mesh is built or any form compiled.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field


from damage_dolfinx.core.errors import InputError  # noqa: F401 (defined with the others)


@dataclass
class ModelParameters:
    """All material, damage and contact data of one run (SI units, plane stress)."""
    E: float = 1e4                 # Young modulus
    nu: float = 0.33               # Poisson ratio
    kappa: float = 1.0             # damage diffusion
    zeta_star: float = 0.01        # lower damage bound
    q_star: float = 1000.0         # strain-energy cap of Psi_q
    variant: str = "B"             # damage source: "A" (1.3) or "B" (1.4)
    lam_D: float = 0.1             # healing
    lam_u: float = 0.0             # variant A: strain-energy driven damage
    lam_u_plus: float = 0.0        # variant B: tension part
    lam_u_minus: float = 0.0       # variant B: compression part
    lam_w: float = 0.0             # threshold
    zeta0: float = 1.0             # initial damage (constant; fields are set by the example)
    L_trunc: float = math.inf      # componentwise stress truncation (2.107)
    stop_at_zeta_star: bool = True  # stop when min zeta reaches zeta_star
    extra: dict = field(default_factory=dict)  # problem-specific data of later sections

    def validate(self, rules=None):
        """The generic checks, and each extra datum by its rule (``rules``: name -> (test,
        what it must be); default EXTRA_RULES, the data shared by several models)."""
        rules = EXTRA_RULES if rules is None else rules
        if not (self.E > 0):
            raise InputError(f"Young modulus E must be positive, got E = {self.E}")
        if not (-1.0 < self.nu < 0.5):
            raise InputError(f"Poisson ratio nu must lie in (-1, 0.5), got nu = {self.nu}")
        if not (0.0 < self.zeta_star < 1.0):
            raise InputError(f"zeta_star must lie in (0, 1), got zeta_star = {self.zeta_star}")
        if not (self.zeta_star <= self.zeta0 <= 1.0):
            raise InputError(f"initial damage zeta0 must lie in [zeta_star, 1] = "
                             f"[{self.zeta_star}, 1], got zeta0 = {self.zeta0}")
        if self.kappa < 0:
            raise InputError(f"damage diffusion kappa must be >= 0, got kappa = {self.kappa}")
        if not (self.q_star > 0):
            raise InputError(f"q_star must be positive, got q_star = {self.q_star}")
        if self.variant not in ("A", "B"):
            raise InputError(f"damage source variant must be 'A' or 'B', got {self.variant!r}")
        for name in ("lam_D", "lam_u", "lam_u_plus", "lam_u_minus", "lam_w"):
            if getattr(self, name) < 0:
                raise InputError(f"{name} must be >= 0, got {getattr(self, name)}")
        if not (self.L_trunc > 0):
            raise InputError(f"L_trunc must be positive (inf for none), got {self.L_trunc}")
        for name, value in self.extra.items():
            rule = rules.get(name)
            if rule is not None and not rule[0](value):
                raise InputError(f"{name} {rule[1]}, got {name} = {value!r}")
        return self

    def replace(self, **changes) -> "ModelParameters":
        known = {f.name for f in dataclasses.fields(self)} - {"extra"}
        extra = dict(self.extra)
        direct = {}
        for key, value in changes.items():
            if key in known:
                direct[key] = _coerce(getattr(self, key), value, key)
            elif key in extra:
                extra[key] = _coerce(extra[key], value, key)
            else:
                raise InputError(f"unknown parameter {key!r}; known: {sorted(known | set(extra))}")
        return dataclasses.replace(self, extra=extra, **direct)

    def as_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d.update(d.pop("extra"))
        return {k: (str(v) if isinstance(v, float) and math.isinf(v) else v) for k, v in d.items()}


#: checks of the data shared by several models, kept in ModelParameters.extra; a model's own
#: data have their rules beside it (``Model.rules``, merged along its classes by
#: ``Model.data_rules()``), and registry.validate applies both
EXTRA_RULES = {
    "c_nu": (lambda v: v > 0, "(normal compliance stiffness) must be positive"),
    "rho": (lambda v: v > 0, "(density) must be positive"),
    "m_visc": (lambda v: v > 0, "(viscosity divisor, A = B/m_visc) must be positive"),
    "history_every": (lambda v: v >= 1 and v == int(v),
                      "(a history.csv row every that many steps) must be a whole number >= 1"),
    "stability_check": (lambda v: v in ("warn", "error", "off"),
                        "(explicit-term time-step check) must be warn, error or off"),
    "damage_active": (lambda v: isinstance(v, bool),
                      "(False: damage frozen at zeta_0, Section 3.1 Ex. 3) must be true or false"),
}


from damage_dolfinx.core.validation import INFINITE_ALLOWED  # noqa: E402,F401 (with the checks)


def _coerce(old, value, key):
    """Convert a command-line string to the type of the current value; any other value is
    checked against that type (validation.number_like: a bool is not a number)."""
    if not isinstance(value, str):
        from damage_dolfinx.core.validation import number_like
        return number_like(old, value, key)
    try:
        if isinstance(old, bool):
            if value.lower() in ("1", "true", "yes", "on"):
                return True
            if value.lower() in ("0", "false", "no", "off"):
                return False
            raise ValueError
        if isinstance(old, (int, float)) and not isinstance(old, bool):
            number = float(value)
        else:
            return value
    except ValueError:
        raise InputError(f"parameter {key}: cannot read {value!r} as {type(old).__name__}") from None
    if math.isnan(number) or (math.isinf(number) and key not in INFINITE_ALLOWED):
        allowed = (" (inf is allowed only for " + ", ".join(sorted(INFINITE_ALLOWED)) + ")"
                   if math.isinf(number) else "")
        raise InputError(f"parameter {key} must be a finite number, got {value!r}{allowed}")
    if 0.0 < abs(number) < 2.2250738585072014e-308:
        raise InputError(f"parameter {key} = {value} underflows (below the smallest normal "
                         "number)")
    return number


@dataclass(frozen=True)
class TimeGrid:
    """Uniform time levels t_n = n k, n = 0..N, N = T/k."""
    k: float
    T: float

    def __post_init__(self):
        if not (self.k > 0):
            raise InputError(f"time step k must be positive, got k = {self.k}")
        if not (self.T > 0):
            raise InputError(f"final time T must be positive, got T = {self.T}")
        ratio = self.T / self.k
        if not math.isfinite(ratio):
            raise InputError(f"T/k = {self.T:g}/{self.k:g} overflows: no run takes that many "
                             "steps")
        if round(ratio) < 1:  # the tolerance below would let any T < 1e-8 k through
            raise InputError(f"final time T = {self.T:g} is below the time step k = {self.k:g}: "
                             "the run would take no step")
        if abs(ratio - round(ratio)) > 1e-8 * max(1.0, ratio):
            raise InputError(f"time step k = {self.k} does not divide T = {self.T} (T/k = {ratio:.6g})")

    @property
    def num_steps(self) -> int:
        return int(round(self.T / self.k))

    def t(self, n: int) -> float:
        return n * self.k
