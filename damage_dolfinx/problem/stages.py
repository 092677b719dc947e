"""The stages of a run, for any :class:`~damage_dolfinx.Problem` (a catalogue example too):
:func:`configure` decides the values of one run (validated data, time grid, mesh level and file),
:func:`on_mesh` builds its mesh on the run's ranks and checks the data against it, and
:func:`build` builds the model from that."""
from __future__ import annotations

import dataclasses
import math
from pathlib import Path

from damage_dolfinx.core.parameters import InputError, TimeGrid

#: more time steps than this need the parameter allow_long (--allow-long)
MAX_STEPS = 10_000_000

#: the readings of the thesis data (``--reading``); a problem without an evidence reading has
#: evidence = literal
READINGS = ("literal", "evidence")


def configure(ex, n=None, k=None, T=None, h=None, overrides=None, mesh_file=None,
              comm=None):
    """``ex`` (under its reading) as one run has it: validated data, T, k, the mesh level and
    file; InputError otherwise (see :meth:`Problem.configure`)."""
    if not ex._checked:  # every problem, a catalogue example too, passes the same checks once
        from damage_dolfinx.problem.checks import check_problem
        ex = check_problem(ex)
    overrides = dict(overrides or {})
    allow_long = bool(overrides.pop("allow_long", False))
    from damage_dolfinx.models.registry import model as model_info, validate
    info = model_info(ex.model)
    # a time step you choose above k_max is refused (stability_check = error) unless the
    # check is set explicitly (--allow-unstable sets warn); the thesis's own steps (defaults,
    # convergence tables) run as the thesis ran them, with a warning above k_max
    action = overrides.pop("stability_check", None) \
        if "stability_check" not in ex.params.extra else overrides.get("stability_check")
    if action is None:
        action = "error" if (k is not None or ex.own) and not ex.allow_unstable \
            else "warn"
        if "stability_check" in ex.params.extra and k is not None:
            overrides["stability_check"] = action
    # validated once: a checked problem's data again only when a run changes them
    params = ex.params if ex._checked and not overrides else \
        validate(info, ex.params.replace(**overrides))
    T = ex.T if T is None else float(T)
    k = ex.default_k(n, h, T, params) if k is None else float(k)
    time = TimeGrid(k, T)
    k_max = info.k_max(params)
    if k > k_max:
        from damage_dolfinx.numerics.stability import check_time_step
        check_time_step(k, k_max, f"{ex.id}: {info.stability_limit}", action=action)
    if n is not None and ex.n is None:
        raise InputError(f"example {ex.id} uses a gmsh mesh: set its size with --h, not --n")
    if h is not None and ex.h is None:
        raise InputError(f"example {ex.id} uses a structured mesh: set it with --n, not --h")
    n = ex.n if n is None else int(n)
    h = ex.h if h is None else float(h)
    # n >= 1 and h > 0 were checked by the entry point (core.validation, by their names)
    if mesh_file is not None and not Path(mesh_file).is_file():
        from damage_dolfinx.core.validation import mesh_path_problem
        raise InputError(f"mesh file {str(mesh_file)!r} "
                         f"{mesh_path_problem(Path(mesh_file)) or 'is not a file'}")
    if time.num_steps > MAX_STEPS and not allow_long:
        raise InputError(f"{time.num_steps} time steps (T = {T:g}, k = {k:g}) is more than "
                         f"{MAX_STEPS:.0e}; choose a larger k, or allow_long=True")
    if mesh_file is not None and ex.dim != 2:
        raise InputError(f"--mesh reads 2-D gmsh meshes; example {ex.id} is {ex.dim}-D")
    if mesh_file is None and not ex.own:
        from mpi4py import MPI
        from damage_dolfinx.problem.resources import check_memory
        # a mesh that cannot fit is refused now (collective on the run's ranks: a serial
        # cell of a convergence study is built on one rank alone)
        check_memory(ex, n, h, comm or MPI.COMM_WORLD)
    sized = dict(n=n, h=h, mesh_file=str(mesh_file) if mesh_file is not None else None) \
        if not ex.own else dict(n=n)
    return dataclasses.replace(ex, params=params, T=T, k=k, _checked=True, **sized)


def on_mesh(c, comm):
    """The configured problem ``c`` on its mesh on ``comm`` (the problem's own, or the mesh file
    replacing it, with the example's tags required), the boundary roles named, checked against
    the loads, law and initial damage: what a model is built from (no solver set up)."""
    from damage_dolfinx.problem.meshes import read_mesh, retag
    from damage_dolfinx.models.registry import model
    from damage_dolfinx.problem.checks import check_data
    if c.mesh_file is not None:
        geometry = read_mesh(c.mesh_file, comm, c.dim)
        required = c.required_tags(comm)
    else:
        geometry = c.make_geometry(comm, c.n, c.h)
        required = None
    built = dataclasses.replace(c, mesh=retag(geometry, c.boundaries, required, model(c.model)))
    check_data(built)  # loads, law, zeta0 against the mesh (validation.py)
    return built


def build(c, comm, contracts=True):
    """The model of the configured problem ``c`` on ``comm``, built on :func:`on_mesh`, and its
    declarations checked against what it built (models/contracts.py; a ContractError): every
    run, study level and sweep point is built here, so none skips the check (``contracts``
    False: not checked, for dd.check_model, which reports every broken declaration)."""
    from damage_dolfinx.models.contracts import ContractError, check, declaration_problems
    from damage_dolfinx.models.registry import model
    cls = model(c.model)
    wrong = declaration_problems(cls) if contracts else []
    if wrong:  # the form of a declaration, before the constructor meets it
        raise ContractError(wrong[0])
    built = cls(on_mesh(c, comm))
    if contracts:
        check(built)
        _check_mesh_limit(c, built)
    return built


def _check_mesh_limit(c, built):
    """A dynamic model's time step against its mesh-dependent limit (Model.mesh_k_max, checked
    by the contracts: a dynamic model that does not give it is refused), refused above it
    unless the problem allows an unstable step (then a warning), like a closed-form limit in
    :func:`configure`; a model that checks its own (``checks_time_step``) is left to it."""
    if not built.dynamic or built.checks_time_step:
        return
    from damage_dolfinx.models.contracts import mesh_k_max
    from damage_dolfinx.numerics.stability import check_time_step
    limit = mesh_k_max(built)
    k = float(c.k)
    if k > limit:
        action = c.params.extra.get("stability_check") or \
            ("warn" if c.allow_unstable else "error")
        check_time_step(k, limit, f"{c.id}: mesh_k_max() of model {built.id}", action=action)
