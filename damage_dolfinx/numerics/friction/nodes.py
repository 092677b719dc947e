"""Contact nodes of Gamma_C: the friction problem's data (:class:`FrictionProblem`) and the owned
vertices with their lumped weights, unit tangents and friction bounds (:class:`ContactNodes`),
shared by every friction solver (nodal quadrature of j(w) = int_{Gamma_C} g |w_tau| ds).

2-D: one tangent per node, v_tau a scalar (arrays of shape (nodes,)). 3-D: a tangent
plane spanned by two orthonormal tangents per node, v_tau a 2-vector (arrays (nodes, 2)); the
faces of Gamma_C must be parallel to coordinate planes (the tangents are then the two other
coordinate axes); other faces are refused (InputError)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from mpi4py import MPI
import ufl
from dolfinx import fem
from petsc4py import PETSc

from damage_dolfinx import compat
from damage_dolfinx.numerics import scalable
from damage_dolfinx.forms.contact import NODAL_QUADRATURE, NODAL_QUADRATURE_3D, tangent, tangential_part
from damage_dolfinx.core.parameters import InputError
from damage_dolfinx.numerics.condensed import lu_direct
from damage_dolfinx.numerics.solvers import SolveContext, spd_direct

#: relative Jacobian shift on contact nodes (units of g per unit slip velocity)
JACOBIAN_SHIFT = 1e-3


@dataclass
class FrictionProblem:
    """Data of one second-kind VI: the unknown ``v``, bilinear ``a`` (UFL, trial/test of V),
    linear ``l`` (UFL, test), Dirichlet ``bcs``, friction bound ``g`` (UFL scalar), the contact
    measure ``dsC`` (ds restricted to Gamma_C) and the solve context."""
    v: fem.Function
    a: object
    l: object
    bcs: list
    g: object
    dsC: object
    context: SolveContext

    @property
    def V(self):
        return self.v.function_space

    @property
    def msh(self):
        return self.V.mesh

    def nodal_ds(self):
        return self.dsC(metadata=NODAL_QUADRATURE if self.dim == 2 else NODAL_QUADRATURE_3D)

    @property
    def dim(self):
        return self.msh.topology.dim

    def tangent(self):
        """The unit tangent (2-D only)."""
        return tangent(ufl.FacetNormal(self.msh))

    def tangential(self, v):
        """v_tau in UFL: the scalar v.tau in 2-D, the vector v - (v.nu) nu in 3-D."""
        if self.dim == 2:
            return ufl.dot(v, self.tangent())
        return tangential_part(v, ufl.FacetNormal(self.msh))

    def tangential_product(self, v, w):
        """v_tau . w_tau in UFL (any dimension)."""
        if self.dim == 2:
            return self.tangential(v) * self.tangential(w)
        return ufl.dot(self.tangential(v), self.tangential(w))


class ContactNodes:
    """Owned vertices of Gamma_C with their lumped weights m_i, unit tangents tau_i and friction
    bounds g_i, all from nodal-quadrature boundary integrals (valid on any straight sides).
    In 3-D ``tau`` has shape (nodes, 2, 3): two coordinate axes per node, ``axes`` (nodes, 2)."""

    def __init__(self, problem: FrictionProblem):
        if problem.dim == 3:
            return self._init_3d(problem)
        w, ds, n_owned = self._weights_and_bounds(problem)
        tm = _assembled(ufl.dot(problem.tangent(), w) * ds).reshape(-1, 2)[:n_owned]
        tau = tm[self.dofs] / self.m[:, None]
        self.tau = tau / np.linalg.norm(tau, axis=1)[:, None]

    def _init_3d(self, problem: FrictionProblem):
        """Weights and bounds as in 2-D; the averaged unit normal of each node must be a
        coordinate axis (a face parallel to a coordinate plane, not an edge between two faces)."""
        msh = problem.msh
        w, ds, n_owned = self._weights_and_bounds(problem)
        nm = _assembled(ufl.dot(ufl.FacetNormal(msh), w) * ds).reshape(-1, 3)[:n_owned]
        normal = nm[self.dofs] / self.m[:, None]
        axis = np.argmax(np.abs(normal), axis=1)
        plane = np.abs(np.abs(normal[np.arange(self.dofs.size), axis]) - 1.0) <= 1e-10
        bad = [normal[~plane][0].round(3).tolist()] if not np.all(plane) else []
        bad = sum(msh.comm.allgather(bad), [])
        if bad:
            raise InputError("Tresca friction in 3-D is implemented on contact faces parallel "
                             "to a coordinate plane only (a contact node has the averaged normal "
                             f"{bad[0]}: a tilted face or an edge between two faces)")
        self.axes = np.sort(np.column_stack([(axis + 1) % 3, (axis + 2) % 3]), axis=1)
        self.tau = np.zeros((self.dofs.size, 2, 3))
        for t in range(2):
            self.tau[np.arange(self.dofs.size), t, self.axes[:, t]] = 1.0

    def _weights_and_bounds(self, problem: FrictionProblem):
        """The owned contact nodes (dofs), their lumped weights m_i and bounds g_i; returns the
        vector test function, the nodal-quadrature measure and the number of owned nodes."""
        V, msh = problem.V, problem.msh
        S = compat.scalar_p1(msh)
        phi, w = ufl.TestFunction(S), ufl.TestFunction(V)
        ds = problem.nodal_ds()
        n_owned = S.dofmap.index_map.size_local
        m = _assembled(phi * ds)[:n_owned]
        self._bound_setup(problem, phi, ds, n_owned)
        gm = _assembled(self._g_form)[:n_owned]
        self.dofs = np.flatnonzero(m > 0)
        if not np.allclose(S.tabulate_dof_coordinates()[self.dofs],
                           V.tabulate_dof_coordinates()[self.dofs]):
            raise RuntimeError("scalar and vector P1 dof numberings differ")  # never seen
        self.m = m[self.dofs]
        self.g = gm[self.dofs] / self.m
        self._check_bound(problem.msh.comm, InputError, "when the friction solver is built")
        return w, ds, n_owned

    def _bound_setup(self, problem, phi, ds, n_owned):
        """The friction bound g may be any UFL scalar: of x (fixed), of Constants (e.g. the
        time), or of Functions of the state (Coulomb: mu p_nu(u_{n-1})). It is evaluated at
        the nodes when the solver is built and again at the start of each solve where it can
        have changed (:meth:`refresh_bound`: Functions in it, or a Constant whose value
        changed). A bound of the friction unknown itself is refused: the solvers hold g fixed
        during a solve (their Jacobian has no dg/dv)."""
        from damage_dolfinx.numerics.held_data import AssembledFrom, held
        g = problem.g
        functions, _ = held(g)
        if any(f is problem.v for f in functions):
            raise InputError("the friction bound g depends on the friction unknown "
                             f"{problem.v.name!r} itself: the friction solvers hold g fixed "
                             "during a solve; write it from the previous step's state (e.g. "
                             "mu p_nu(u_old), blocks.coulomb_friction_bound)")
        self._g_form = compat.form(g * phi * ds)
        self._g_functions = functions
        self._g_constants = AssembledFrom(g, problem.msh.comm, functions=False)
        self._n_owned = n_owned
        #: True: g is refreshed before every solve (it holds Functions)
        self.variable_bound = bool(functions)
        self.bound_refreshes = 0

    def refresh_bound(self) -> bool:
        """Evaluate g at the nodes again (in place: every solver sees the new g) if it can have
        changed since the last evaluation; True if it was evaluated. A bound of x and fixed
        Constants (the thesis models) is never evaluated again."""
        constants_changed = self._g_constants.changed()  # (bytes: under a us per Constant)
        if not self.variable_bound and not constants_changed:
            return False
        b = getattr(self, "_g_vec", None)
        if b is None:  # made once: the bound is assembled into it at every refresh
            b = self._g_vec = compat.create_vector(self._g_form)
        with b.localForm() as bl:
            bl.set(0.0)
        compat.assemble_vector(b, self._g_form)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        self.g[:] = b.getArray(readonly=True)[self.dofs] / self.m  # owned entries
        from damage_dolfinx.core.errors import ConvergenceError
        self._check_bound(self._comm, ConvergenceError, "at the start of a friction solve")
        self.bound_refreshes += 1
        return True

    def _check_bound(self, comm, error, when):
        """The bound at the contact nodes is finite and >= 0 (a negative one would push the
        slip on instead of resisting it), on every rank alike; ``error`` raised otherwise."""
        self._comm = comm
        g = self.g
        finite = bool(np.isfinite(g).all())
        values = np.array([g.min() if g.size and finite else np.inf,
                           -np.abs(g).max() if g.size and finite else 0.0, 0.0 if finite else -1.0])
        if comm.size > 1:  # one reduction: min g, max |g|, any node not finite
            comm.Allreduce(MPI.IN_PLACE, values, op=MPI.MIN)
        low, largest, finite = values[0], -values[1], values[2] == 0.0
        if not finite:
            raise error(f"the friction bound g is not finite (NaN or Inf) at a contact node "
                        f"{when}: its data (mu, c_nu, the state it is written from) overflow")
        if low < -1e-12 * max(1.0, largest):
            raise error(f"the friction bound g is negative at a contact node {when} (min "
                        f"{low:.6g}): a friction bound is >= 0 (e.g. mu >= 0 and c_nu >= 0 in "
                        "mu p_nu(u))")

    @property
    def dim(self) -> int:
        return self.tau.shape[-1]

    def rows(self):
        """Local indices of the tangential dofs (owned): (nodes,) in 2-D, (nodes, 2) in 3-D."""
        if self.dim == 2:
            return 2 * self.dofs + np.argmax(np.abs(self.tau), axis=1)
        return 3 * self.dofs[:, None] + self.axes

    def tangential(self, v):
        """v_tau at the contact nodes (owned); ``v`` a Function or a PETSc Vec. Shape (nodes,) in
        2-D, (nodes, 2) in 3-D."""
        array = v.x.array if hasattr(v, "x") else v.getArray(readonly=True)
        if self.dim == 3:
            return np.einsum("ic,itc->it", array.reshape(-1, 3)[self.dofs], self.tau)
        return np.einsum("ic,ic->i", array.reshape(-1, 2)[self.dofs], self.tau)

    def add_tangential_load(self, b: PETSc.Vec, force):
        """b_i -= m_i force_i tau_i on the owned contact nodes (the nodal integral of force w_tau;
        ``force`` (nodes,) in 2-D, (nodes, 2) in 3-D)."""
        if self.dim == 3:
            arr = b.getArray().reshape(-1, 3)
            arr[self.dofs] -= np.einsum("it,itc->ic", self.m[:, None] * force, self.tau)
            b.setArray(arr.reshape(-1))
            return
        arr = b.getArray().reshape(-1, 2)  # owned part
        arr[self.dofs] -= (self.m * force)[:, None] * self.tau
        b.setArray(arr.reshape(-1))


def linear_defaults(V, symmetric=True) -> dict:
    """KSP defaults of the friction solves on V: direct (Cholesky; LU for a non-symmetric
    matrix) in 2-D and 3-D. Not the AMG of scalable.py: the stick blocks m g/eps (eps = 1e-9)
    make the Jacobian ~1e9 times stiffer on the contact dofs than elsewhere, and CG + GAMG
    (rtol 1e-10) did not give usable Newton directions: on 2.2-ex1-3d at n = 16 its Newton
    stopped at the iteration limit, where Cholesky converges in a few iterations per step.
    ``-friction_ksp_type cg -friction_pc_type gamg`` etc. still select it (with the rigid-body
    modes of ``near_nullspace``)."""
    return spd_direct(V.mesh.comm) if symmetric else lu_direct(V.mesh.comm)


def newton_linear(V) -> dict:
    """KSP defaults of the friction Newton: ``linear_defaults`` in 2-D; in 3-D CG on J
    preconditioned by the Cholesky factorisation of an earlier J (newton.LAG_MAX_ITS_3D), to
    rtol 1e-12 of the true residual."""
    if V.mesh.topology.dim == 2:
        return linear_defaults(V)
    return {**linear_defaults(V), "ksp_type": "cg", "ksp_norm_type": "unpreconditioned",
            "ksp_rtol": 1e-12, "ksp_atol": 1e-50, "ksp_max_it": 200}


def near_nullspace(V):
    """The rigid-body modes of a 3-D V (for an AMG chosen by options), None in 2-D."""
    return scalable.rigid_body_modes(V) if V.mesh.topology.dim == 3 else None


def _assembled(L) -> np.ndarray:
    """Local array (owned + ghost values summed across ranks) of an assembled linear form
    (UFL, or already compiled)."""
    f = L if not isinstance(L, ufl.Form) else compat.form(L)
    b = compat.create_vector(f)
    with b.localForm() as bl:
        bl.set(0.0)
    compat.assemble_vector(b, f)
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    b.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
    with b.localForm() as bl:
        return bl.array.copy()

