"""What the figures say: ASCII names as matplotlib mathtext (Gamma_D -> Γ_D, zeta -> ζ, the
convergence error definitions) and the amplification factor of a deformed-shape figure, rounded
to the 1-2-5 series (or the factor the thesis states) and written in its title. Pure Python;
figstyle.py draws and re-exports these names.
"""
from __future__ import annotations

import math
import re


#: factors stated in thesis captions (2.12 x3, 3.4 x4); kept as the thesis prints them
THESIS_FACTORS = (3.0, 4.0)


_MATH = [  # (pattern, replacement), applied in order to ASCII labels
    (r"\bvon Mises stress\b", r"von Mises stress $\\sigma_{VM}$"),
    (r"\bvon Mises norm of the strain\b", r"von Mises norm of the strain $\\varepsilon_{VM}$"),
    (r"\bGamma_([DNC])\b", r"$\\Gamma_\1$"),
    (r"\bzeta_star\b", r"$\\zeta^*$"),
    (r"\bdamage zeta\b", "damage"),
    (r"\bzeta\b", r"$\\zeta$"),
    (r"\bsigma_tau\b", r"$\\sigma_\\tau$"),
    (r"\bsigma_nu\b", r"$\\sigma_\\nu$"),
    (r"\bu_tau\b", r"$u_\\tau$"),
    (r"\bu_(\d)\b", r"$u_\1$"),
    (r"\bx([12])\b(?=\s*[=\[,)])(?<!\(x[12])", r"$x_\1$"),  # x1 [m], x2 = 3; not '(x2)' factors
    (r"\beps_reg\b", r"$\\varepsilon$"),
]


def mathtext(label: str) -> str:
    """ASCII names in a label -> matplotlib mathtext (Gamma_D -> $\\Gamma_D$, zeta -> $\\zeta$,
    x1 -> $x_1$, u_1 -> $u_1$, von Mises stress -> ... $\\sigma_{VM}$)."""
    if "$" in label:
        return label
    for pattern, repl in _MATH:
        label = re.sub(pattern, repl, label)
    return label


def error_mathtext(definition: str) -> str:
    """A convergence error definition (convergence.py) in mathtext:
    'max_n (||u - u_hk||_V + ||zeta - zeta_hk||_L2)' -> max_n (‖u - u^hk‖_V + ...), the norms
    between double bars (``\\Vert``)."""
    greek = {"zeta": r"\zeta", "sigma": r"\sigma", "eta": r"\eta"}

    def norm(m):
        x = greek.get(m.group(1), m.group(1))
        space = {"L2": "L^2"}.get(m.group(2), m.group(2))
        return rf"\Vert {x} - {x}^{{hk}}\Vert_{{{space}}}"  # (mathtext's \| is a single bar)
    text = re.sub(r"\|\|(\w+) - \1_hk\|\|_(\w+)", norm, definition)
    if text == definition:
        return mathtext(definition)
    return "$" + text.replace("max_n", r"\max_n\,") + "$"


def round_amplification(a: float) -> float:
    """The largest factor of the 1-2-5 series (x 10^k) not above ``a`` (0 stays 0)."""
    if not a or not math.isfinite(a) or a <= 0:
        return 0.0 if not a else 1.0
    exp = math.floor(math.log10(a))
    for m in (5.0, 2.0, 1.0):
        if m * 10.0 ** exp <= a * (1 + 1e-9):
            return float(f"{m * 10.0 ** exp:.12g}")
    return float(f"{10.0 ** exp:.12g}")


def is_round(a: float) -> bool:
    """True for 0 (undeformed), the 1-2-5 series and the thesis's own factors."""
    if a == 0 or a in THESIS_FACTORS:
        return True
    return a > 0 and abs(round_amplification(a) - a) <= 1e-9 * a


def drawn_amplification(a: float) -> float:
    """The factor a figure is drawn with: ``a`` if round (or a thesis factor), else rounded."""
    return a if is_round(a) else round_amplification(a)


def amplification_text(a: float) -> str:
    """How the title states the factor ('' for the undeformed configuration)."""
    if not a:
        return "undeformed configuration"
    if a == 1:
        return "true displacements (×1)"
    if a < 1:
        return f"displacements shrunk ×{a:g}"
    return f"displacements ×{a:g}"


#: what a model parameter is, for an axis: (description, symbol in mathtext); the names of
#: docs/models.md ("Common notation" and each model's data)
PARAMETERS = {
    "E": ("Young's modulus", "$E$"), "nu": ("Poisson's ratio", r"$\nu_P$"),
    "kappa": ("damage diffusion", r"$\kappa$"), "zeta_star": ("damage bound", r"$\zeta_*$"),
    "q_star": ("strain-energy cap", r"$q_*$"), "lam_D": ("healing rate", r"$\lambda_D$"),
    "lam_u": ("damage rate", r"$\lambda_u$"),
    "lam_u_plus": ("tension damage rate", r"$\lambda_u^+$"),
    "lam_u_minus": ("compression damage rate", r"$\lambda_u^-$"),
    "lam_w": ("damage threshold", r"$\lambda_w$"), "zeta0": ("initial damage", r"$\zeta_0$"),
    "L_trunc": ("stress truncation", "$L$"), "m_visc": ("viscosity ratio", r"$m_{visc}$"),
    "g_fric": ("friction bound", "$g$"), "mu_f": ("friction coefficient", r"$\mu_f$"),
    "c_nu": ("normal compliance", r"$c_\nu$"), "gap": ("initial gap", "$g_0$"),
    "rho": ("density", r"$\rho$"), "eps_reg": ("friction regularisation", r"$\varepsilon$"),
}

#: what a final scalar of a run is (sweep.csv, summary.json "final"), for an axis
SCALARS = {
    "u_L2": r"$\Vert u\Vert_{L^2}$", "eps_u_L2": r"$\Vert\varepsilon(u)\Vert_{L^2}$",
    "zeta_min": r"min $\zeta$ (1 = sound)", "zeta_max": r"max $\zeta$ (1 = sound)",
    "zeta_mean": r"mean $\zeta$ (1 = sound)", "wall_time_s": "wall time [s]",
    "steps_done": "time steps done", "t_final": "final time $t$",
}


def parameter_label(name: str) -> str:
    """An axis or legend label for the model parameter ``name``: 'damage diffusion κ
    (kappa)'; a name of an own model's data stays as it is."""
    if name not in PARAMETERS:
        return name
    what, symbol = PARAMETERS[name]
    return f"{what} {symbol} ({name})"


def scalar_label(name: str) -> str:
    """An axis label for the final scalar ``name`` of a run: its quantity in mathtext (the
    contact and friction resultants through :func:`mathtext`), the column's name beside it."""
    if name in SCALARS:
        return f"{SCALARS[name]}  [{name}]" if name not in ("wall_time_s",) else SCALARS[name]
    return name.replace("_", " ") + f"  [{name}]"
