"""The public building blocks of the models: what a model of your own is made of.

Every model of the package is written with these, and so can yours (docs: "Writing a model";
``demos/demo_own_model.py``). The weak forms in UFL are in :mod:`damage_dolfinx.forms`.

Constitutive maps (Chapter 1; UFL, any dimension):
    :func:`eps` (symmetric gradient), :func:`B` (isotropic elasticity; plane stress in 2-D),
    :func:`Phi_L` (truncation at L, (2.106)), :func:`eta_star` (max(zeta, zeta*)),
    :func:`von_mises`.
Stresses:
    :func:`kelvin_voigt_stress` A eps(v) + zeta Phi_L(B eps(u)); :func:`viscous_stress`
    A eps(v) = B eps(v)/m_visc; :func:`damaged_elastic_stress` zeta Phi_L(B eps(u));
    :func:`memory_stress` B eps(u) - M (long memory, 2.3) with :class:`MemoryKernel` and
    :class:`MemoryTerm` (the memory M_n = sum_j k kernel(t_n - t_j) g_j, recursive form).
The damage step:
    :class:`DamageStep` (zeta_n from zeta_{n-1} and the source phi: the obstacle inclusion in
    [zeta*, 1] by SNES vinewtonrsls, or the linear PDE), :class:`~damage_dolfinx.DamageLaw`.
Contact laws:
    :func:`normal_compliance_pressure` p_nu(u.nu - g) = c_nu (u.nu - g)_+ and
    :func:`normal_compliance_term` (its boundary integral); :func:`bilateral` (u.nu = 0 on
    faces parallel to coordinate planes, a component Dirichlet condition); Tresca friction
    j(w) = int g abs(w_tau) through :class:`FrictionProblem` and a friction solver;
    :func:`coulomb_bound` the simplified Coulomb bound mu_f abs(S_n) (a Tresca bound g);
    :func:`coulomb_friction_bound` Coulomb friction with normal compliance, the bound
    g = mu p_nu(u_{n-1}) of the previous step's displacement (a bound of the state: the friction
    solver evaluates it at the start of every solve).
Friction solvers (second-kind inequalities, prefix ``friction_``):
    :class:`RegularisedNewton` (Newton on the regularised law Phi_eps), :func:`friction_solver`
    (a solver by name: ``newton``, or a registered alternative), :data:`FRICTION_DEFAULTS`.
Boundary conditions:
    :func:`clamped` (u = 0 on a tag).
Spaces and fields:
    :func:`vector_p1`, :func:`scalar_p1` (P1 Lagrange), :func:`scalar_dg0`, :func:`tensor_dg0`,
    :func:`interpolate` (a Function from a UFL expression or a function of x),
    :func:`expression` (a compiled UFL expression for :func:`interpolate`).
Stability of explicit terms:
    :func:`estimate_k_max` (largest eigenvalue of M^-1 K with the viscosity C; MPI),
    :func:`check_time_step` (k against k_max: error, warn or off).
Solvers:
    :class:`LinearSolver`, :class:`NonlinearSolver` (PETSc options prefixes),
    :class:`SolveContext`, :class:`ConvergenceError`.
"""
from damage_dolfinx.compat import (expression, interpolate, scalar_dg0, scalar_p1, tensor_dg0,
                                   vector_p1)
from damage_dolfinx.forms.kelvin_voigt import (damaged_elastic_stress, kelvin_voigt_stress,
                                               viscous_stress)
from damage_dolfinx.forms.elastic_damage import load
from damage_dolfinx.forms.viscoelastic_memory import total_stress as memory_stress
from damage_dolfinx.models.laws import DamageLaw, thesis_law
from damage_dolfinx.numerics.boundary import bilateral_plane_faces as bilateral, clamped
from damage_dolfinx.forms.constitutive import B, Phi_L, eps, eta_star, von_mises
from damage_dolfinx.forms.contact import (normal_compliance_pressure, normal_compliance_term,
                                             positive_part)
from damage_dolfinx.numerics.damage import DamageStep
from damage_dolfinx.numerics.friction import (FRICTION_DEFAULTS, OMEGA_PD, RHO_UZAWA,
                                              FrictionProblem, RegularisedNewton,
                                              make_solver as friction_solver)
from damage_dolfinx.numerics.memory import MemoryKernel, MemoryTerm
from damage_dolfinx.numerics.solvers import (ConvergenceError, LinearSolver, NonlinearSolver,
                                             SolveContext)
from damage_dolfinx.numerics.stability import check_time_step, estimate_k_max

__all__ = ["B", "ConvergenceError", "DamageLaw", "DamageStep", "FRICTION_DEFAULTS",
           "FrictionProblem", "LinearSolver", "MemoryKernel", "MemoryTerm", "NonlinearSolver",
           "OMEGA_PD", "Phi_L", "RHO_UZAWA", "RegularisedNewton", "SolveContext", "bilateral",
           "check_time_step", "clamped", "coulomb_bound", "coulomb_friction_bound", "damaged_elastic_stress", "eps",
           "estimate_k_max", "eta_star", "expression", "interpolate", "scalar_dg0", "scalar_p1",
           "tensor_dg0", "vector_p1", "friction_solver", "kelvin_voigt_stress", "load",
           "memory_stress", "normal_compliance_pressure", "normal_compliance_term",
           "positive_part", "thesis_law", "viscous_stress", "von_mises"]


def coulomb_bound(mu_f, S_n):
    """The simplified Coulomb friction bound g = mu_f abs(S_n) for a prescribed normal stress S_n
    (Section 2.4, P2): Tresca friction with this bound."""
    return mu_f * abs(S_n)


def coulomb_friction_bound(mu, u_old, normal, c_nu, gap=0.0):
    """The Coulomb friction bound g = mu p_nu(u_old) = mu c_nu (u_old . nu - gap)_+ of normal
    compliance, for :class:`FrictionProblem`: ``u_old`` is the previous step's displacement (a
    Function the step copies in ``old_state``), so the bound is explicit in time and the friction
    solve keeps its Jacobian (g does not depend on its unknown). The solver evaluates it at the
    contact nodes at the start of every solve (a bound of the friction unknown itself is
    refused). Used by ``demos/demo_coulomb_friction.py``."""
    return mu * normal_compliance_pressure(u_old, normal, c_nu, gap)
