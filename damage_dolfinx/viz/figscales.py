"""The scales of a figure: damage on the fixed colour scale [zeta*, 1] (widened, never
autoscaled, only when the field leaves it), stresses on one scale within a thesis pair, a
narrow damage range flagged for its own panel, stress units written with an SI prefix. Pure
NumPy; figstyle.py draws and re-exports these names.
"""
from __future__ import annotations

import math
import re

import numpy as np


def is_damage(name: str, label: str = "") -> bool:
    return name == "zeta" or "zeta" in label.lower() or "damage" in label.lower()


def damage_limits(values, zeta_star: float, tol: float = 1e-9):
    """(vmin, vmax, note): [zeta*, 1] unless the field leaves it; then the actual extremes,
    and ``note`` says so (printed in the panel title)."""
    v = np.asarray(values, float)
    lo, hi = float(np.nanmin(v)), float(np.nanmax(v))
    vmin, vmax, notes = zeta_star, 1.0, []
    if lo < zeta_star - tol:
        vmin = lo
        notes.append(f"min $\\zeta$ = {lo:.3g} < $\\zeta^*$")
    if hi > 1 + tol:
        vmax = hi
        notes.append(f"max $\\zeta$ = {hi:.3g} > 1")
    return vmin, vmax, "; ".join(notes)


def shared_limits(arrays):
    """(0, max) over several arrays: one stress scale for the panels of a thesis pair."""
    return 0.0, max(float(np.nanmax(np.asarray(a, float))) for a in arrays)


#: SI prefixes a stress scale is written in (never a "1e6" multiplier over the colour bar)
SI_PREFIXES = ((1e9, "G"), (1e6, "M"), (1e3, "k"), (1.0, ""))


def si_unit(label: str, vmax: float):
    """(label, scale): a label ending in a unit ``[Pa]`` (or ``[N]``, ``[m]`` ...) rewritten
    with the SI prefix that keeps the largest value below 1000 (``[MPa]``, scale 1e6); other
    labels unchanged (scale 1)."""
    m = re.search(r"\[(Pa|N|N/m|N/m\^?2|J)\]$", label)
    if not m or not vmax or not math.isfinite(vmax):
        return label, 1.0
    scale, prefix = next(((f, p) for f, p in SI_PREFIXES if abs(vmax) >= f), (1.0, ""))
    return label[:m.start()] + f"[{prefix}{m.group(1)}]", scale


def damage_ticks(vmin, vmax, zeta_star):
    ticks = [t for t in np.linspace(0, 1, 6) if vmin <= t <= vmax]
    if vmin <= zeta_star <= vmax and all(abs(t - zeta_star) > 0.05 * (vmax - vmin) for t in ticks):
        ticks = [zeta_star] + ticks
    if vmin < zeta_star:
        ticks = [vmin] + [t for t in ticks if t - vmin > 0.08 * (vmax - vmin)]
    return sorted(ticks)


#: a damage field whose range covers less than this fraction of [zeta*, 1] is one colour on the
#: fixed scale: the figure adds a panel on the field's own range (red frame on the fixed bar)
NARROW_DAMAGE = 0.05
#: a body whose damage stays within this of zeta* (in units of 1 - zeta*) is fully damaged
FULLY_DAMAGED = 0.09


def narrow_damage(lo: float, hi: float, zeta_star: float) -> bool:
    """True when the damage range [lo, hi] is too narrow to be seen on the fixed [zeta*, 1]
    scale but not constant (a constant field has nothing to stretch) and the body is not
    fully damaged (a pattern inside a fully damaged body would mislead)."""
    return (hi - lo < NARROW_DAMAGE * (1 - zeta_star) and hi - lo > 1e-6
            and hi > zeta_star + FULLY_DAMAGED * (1 - zeta_star))


def range_decimals(lo: float, hi: float, nticks: int = 4) -> int:
    """Decimals that write ticks over [lo, hi] as distinct numbers (never '1, 1, 0.9999')."""
    step = (hi - lo) / max(1, nticks)
    return int(min(8, max(0, math.ceil(-math.log10(step)) if step > 0 else 2)))


def range_text(lo: float, hi: float) -> str:
    """"[lo, hi]" with 3 significant digits, more where 3 would write two different values
    as one (a damage range [0.9999969, 1] is never titled "[1, 1]")."""
    digits = 3
    while lo != hi and digits < 12 and f"{lo:.{digits}g}" == f"{hi:.{digits}g}":
        digits += 1
    return f"[{lo:.{digits}g}, {hi:.{digits}g}]"
