"""The final scalars of a run known before any work: the names a run's summary.json holds in
its ``final`` block (and a sweep's table in its columns), from the model class and the
configured problem, without building the model.

A run reports (``Model.scalars()`` and the contact outputs the run attaches,
numerics/contact_output.py):

* the base scalars of every model, ``Model.base_scalars`` (u_L2, eps_u_L2, zeta min/max/mean);
* the model's own columns, ``Model.declared_columns(problem, dim)`` (its ``history_columns``,
  or what its data select: a probe, named contact faces), except the step statistics
  (iteration counts, named ``*_its``), which go to history.csv but not to the scalars;
* the contact outputs when the run has a contact boundary Gamma_C: named by a contact role
  of the model in ``problem.boundaries``, or, without ``boundaries``, the mesh's facet tag 3
  (non-empty); with the friction force and the sliding part when the model's contact has
  friction (a ``tresca`` or ``coulomb`` role).

tests/test_sweep_plot.py checks, for every model of the package, that these names are those of
a built model's ``final`` block after a step, so that the two cannot drift apart.
"""
from __future__ import annotations

from damage_dolfinx.core.parameters import InputError

#: the scalars every model reports (Model.scalars)
BASE_SCALARS = ("u_L2", "eps_u_L2", "zeta_min", "zeta_max", "zeta_mean")
#: the ending of a step statistic's column (an iteration count: history.csv only)
STEP_STATISTIC = "_its"
#: the contact roles whose contact has friction (its outputs add the friction force)
FRICTION_ROLES = ("tresca", "coulomb")


def has_contact(model_class, problem, geometry, comm) -> bool:
    """The run of ``problem`` on ``geometry`` (the mesh before its boundary roles are named)
    has a contact boundary Gamma_C (collective on ``comm``)."""
    import numpy as np
    from mpi4py import MPI
    from damage_dolfinx.core.tags import GAMMA_C
    if not model_class.contact_roles:
        return False
    if problem.boundaries is not None:  # every named part is non-empty (meshes.retag)
        return any(role in problem.boundaries for role in model_class.contact_roles)
    values = geometry.facet_tags.values
    return comm.allreduce(int(np.sum(values == GAMMA_C)), op=MPI.SUM) > 0


def final_scalar_names(problem, geometry, comm) -> list:
    """The names of the final scalars of a run of ``problem`` (configured: its model, data and
    builders) on ``geometry``, in the order of history.csv (see the module's docstring)."""
    from damage_dolfinx.models.registry import model
    from damage_dolfinx.numerics.contact_output import ContactOutput
    cls = model(problem.model)
    dim = geometry.mesh.topology.dim
    names = list(BASE_SCALARS) + [c for c in cls.declared_columns(problem, dim)
                                  if not c.endswith(STEP_STATISTIC)]
    if has_contact(cls, problem, geometry, comm):
        friction = any(role in FRICTION_ROLES for role in cls.contact_roles)
        names += ContactOutput.names(dim, friction)
    return names


def predicted(problem) -> bool:
    """The final scalars of ``problem``'s model are known before it is built: a model of the
    package (a model of your own may add columns in its constructor; its plot is checked
    after the runs)."""
    from damage_dolfinx.models.registry import model
    return model(problem.model).__module__.startswith("damage_dolfinx.")


def check_plot(plot, problem, geometry, comm, what="plot"):
    """InputError (before any work) when ``plot`` is not a final scalar of a run of
    ``problem`` on ``geometry``; nothing to check when ``plot`` is None or the model is not
    the package's (:func:`predicted`)."""
    if plot is None or not predicted(problem):
        return
    names = final_scalar_names(problem, geometry, comm)
    if plot not in names:
        raise InputError(f"{what} {plot!r} is not one of the final scalars a run of "
                         f"{problem.id!r} (model {problem.model_id}) reports: "
                         f"{', '.join(names)}")
