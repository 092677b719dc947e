"""``damage-dolfinx show ID``: an example's data before running it (the values a ``run ID``
with the same --set and --reading would use): model, mesh, n or h, k, T, the reading and its
departures, every parameter, the default convergence study."""
from __future__ import annotations

import dataclasses


def show(case_id, overrides) -> str:
    """The text of ``show`` for a case id (catalogue, registered example or model example)."""
    from damage_dolfinx.models.registry import model as model_info
    from damage_dolfinx.runtime.cases import resolve
    ex = resolve(case_id, overrides)
    run = ex.configure(overrides={k: v for k, v in overrides.items() if k != "reading"})
    info = model_info(ex.model)
    lines = [f"{case_id}: {getattr(ex, 'title', '') or info.title}"]
    section = "" if getattr(ex, "own", True) else getattr(ex, "section", "")
    lines.append(f"  model      {info.id} ({info.title})" + (f", thesis Section {section}"
                                                            if section else ""))
    if run.h is not None:
        mesh = f"gmsh mesh, element size h = {run.h:g} (--h)"
    elif run.n is not None:
        mesh = f"structured mesh family, n = {run.n} cells per side (--n)"
    else:
        mesh = "one mesh (no level)"
    lines.append(f"  mesh       {mesh}")
    import math
    k_max = info.k_max(run.parameters() if hasattr(run, "parameters") else run.params)
    limit = f"; k_max = {k_max:.4g} ({info.stability_limit})" if math.isfinite(k_max) else ""
    lines.append(f"  time       k = {run.time.k:g}, T = {run.time.T:g}, "
                 f"{run.time.num_steps} steps{limit}")
    reading = getattr(run, "reading", None) or "literal"
    readings = ["literal", *getattr(ex, "readings", {})]
    lines.append(f"  reading    {reading} (default {getattr(ex, 'default_reading', 'literal')};"
                 f" available: {', '.join(dict.fromkeys(readings))})")
    params = run.params
    lines.append("  parameters (--set NAME=VALUE)")
    values = {f.name: getattr(params, f.name) for f in dataclasses.fields(params)
              if f.name != "extra"}
    values.update(params.extra)
    width = max(map(len, values)) if values else 0
    for name, value in values.items():
        lines.append(f"    {name:{width}s} = {value!r}")
    conv = getattr(ex, "convergence", None)
    if conv:
        lines.append(f"  converge   reference n = {conv.get('ref_n')}, k = {conv.get('ref_k')}; "
                     f"levels n = {conv.get('n')}, k = {conv.get('k')}")
    assumptions = [a for a in getattr(run, "assumptions", []) or [] if a.startswith("reading:")]
    lines += [f"  {a}" for a in assumptions]
    return "\n".join(lines)
