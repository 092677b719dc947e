"""The regularised friction residual (2.99) and its convex energy, algebraically: one
matrix-vector product per Newton iteration, no form assembly (:class:`AlgebraicResidual`)."""
from __future__ import annotations

import numpy as np
from dolfinx import fem
from petsc4py import PETSc

from damage_dolfinx import compat
from damage_dolfinx.numerics.friction import law
from damage_dolfinx.numerics.friction.nodes import ContactNodes, FrictionProblem

class AlgebraicResidual:
    """The residual of the regularised problem (2.99) without form assembly:

        F(v) = A v - b + sum_i m_i Phi_eps(v_tau,i) tau_i   (Dirichlet rows: v - v_D),

    A the matrix of the constant form ``a`` (Dirichlet rows and columns eliminated, assembled
    once), b the lifted right-hand side ``l`` (assembled once per time step by
    :meth:`assemble_rhs`), the friction forces nodal (ContactNodes). One matrix-vector product
    per Newton iteration instead of an assembly over all cells. It equals the assembled UFL
    residual where Gamma_C is straight; :meth:`matches` checks that."""

    def __init__(self, problem: FrictionProblem, nodes: ContactNodes, eps: fem.Constant):
        self.p, self.nodes, self.eps = problem, nodes, eps
        self.a, self.l = compat.form(problem.a), compat.form(problem.l)
        self.A = compat.create_matrix(self.a)
        compat.assemble_matrix(self.A, self.a, problem.bcs)
        self.A.assemble()
        self.b = compat.create_vector(self.l)
        self._v = compat.petsc_vec(problem.v)
        self._work = [self.b.duplicate() for _ in range(3)]  # energy_change: d, s, A d
        #: callables given b right after l is assembled into it (before the lifting, the ghost
        #: update and the boundary values), e.g. the contact outputs' reaction rows
        self.rhs_taps = []

    def assemble_rhs(self):
        with self.b.localForm() as bl:
            bl.set(0.0)
        compat.assemble_vector(self.b, self.l)
        for tap in self.rhs_taps:
            tap(self.b)
        compat.apply_lifting(self.b, self.a, self.p.bcs)
        self.b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        compat.set_bc(self.b, self.p.bcs)

    def __call__(self, x, r):
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        x.copy(self._v)  # the (UFL) Jacobian is assembled from v
        self.p.v.x.scatter_forward()
        self.A.mult(x, r)
        r.axpy(-1.0, self.b)
        phi = law.phi(self.nodes.tangential(x), self.nodes.g, self.eps.value)
        self.nodes.add_tangential_load(r, -phi)
        compat.set_bc(r, self.p.bcs, x, -1.0)

    def energy_change(self, x, x0) -> float:
        """E(x) - E(x0) of the convex energy 1/2 a(v,v) - l(v) + j_eps(v) whose gradient is this
        residual: 1/2 (x + x0)^T A (x - x0) - b^T (x - x0) + sum_i m_i (F_eps(x_tau,i) -
        F_eps(x0_tau,i)) (2.101), without cancellation against the large |E|."""
        d, s, Ad = self._work
        x.copy(d)
        d.axpy(-1.0, x0)
        x.copy(s)
        s.axpy(1.0, x0)
        self.A.mult(d, Ad)
        quadratic = 0.5 * s.dot(Ad) - self.b.dot(d)
        eps, g, m = float(self.eps.value), self.nodes.g, self.nodes.m
        local = float(np.sum(m * (law.potential(self.nodes.tangential(x), g, eps)
                                  - law.potential(self.nodes.tangential(x0), g, eps))))
        return quadratic + self.p.msh.comm.allreduce(local)

    def matches(self, form_residual, rtol=1e-10) -> bool:
        """True if this residual equals the assembled one (``form_residual``) at two test
        velocities, one slipping and one near the stick threshold, on every rank."""
        saved = self.p.v.x.array.copy()
        pattern = test_pattern(self.p.V)
        self.assemble_rhs()
        x, r1, r2 = self._v.copy(), self.b.duplicate(), self.b.duplicate()
        worst = 0.0
        for scale in (1.0, 2.0 * float(self.eps.value)):
            with x.localForm() as xl:
                xl.array[:] = scale * pattern
            self(x, r1)
            form_residual(x, r2)
            r1.axpy(-1.0, r2)
            worst = max(worst, r1.norm(PETSc.NormType.INFINITY)
                        / max(r2.norm(PETSc.NormType.INFINITY), 1e-300))
        self.p.v.x.array[:] = saved
        return worst <= rtol


def test_pattern(V) -> np.ndarray:
    """A smooth, nowhere-special velocity field on V (local array) at which residuals and
    Jacobians are compared; in 3-D its third component mixes all three coordinates."""
    dim = V.mesh.topology.dim
    X = V.tabulate_dof_coordinates()[:, :dim]
    columns = [np.sin(3.0 * X[:, 0] + 1.0) + np.cos(5.0 * X[:, 1]),
               np.cos(2.0 * X[:, 0]) - np.sin(4.0 * X[:, 1] + 0.5)]
    if dim == 3:
        columns = [c + 0.5 * np.sin(2.0 * X[:, 2] + k) for k, c in enumerate(columns)]
        columns.append(np.sin(X[:, 0] + 2.0 * X[:, 1] - 3.0 * X[:, 2]))
    return np.column_stack(columns).ravel()
