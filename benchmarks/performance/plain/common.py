"""What the straightforward scripts share: the command line, the example's mesh and data, P1
spaces, an LU solver, the damage obstacle step by SNES vinewtonrsls, a plain SNES Newton, and
the outputs (XDMF every N/20 steps, history.csv every step, final.npz).

Each script is still written as a DOLFINx user would write it: UFL forms compiled once,
``dolfinx.fem.petsc`` assembly, PETSc solvers with fixed options. Only the data (parameters,
loads, mesh) and the UFL forms come from the package, so both sides solve the same discrete
problem."""
import argparse
import math
import time
from pathlib import Path

import numpy as np
import ufl
from dolfinx import fem, io
from dolfinx.fem import petsc as fpetsc
from mpi4py import MPI
from petsc4py import PETSc

from damage_dolfinx.catalogue import examples
from damage_dolfinx.forms.damage import damage_step_forms

comm = MPI.COMM_WORLD


class Setting:
    """The example's data and mesh at the command line's n, k: ``ex, p, x_ (params.extra),
    msh, tags, V, Z, k, N, t_c, x, ds, n_f, out``."""

    def __init__(self, example_id, n, k, out):
        ap = argparse.ArgumentParser()
        ap.add_argument("--n", type=int, default=n)
        ap.add_argument("--k", type=float, default=k)
        ap.add_argument("--T", type=float, default=None)
        ap.add_argument("--out", default=out)
        args = ap.parse_args()
        self.out = Path(args.out)
        self.out.mkdir(parents=True, exist_ok=True)
        self.ex = examples.get(example_id)  # the data only: parameters, loads, mesh
        self.p, self.x_ = self.ex.params, self.ex.params.extra
        geometry = self.ex.make_geometry(comm, args.n, None)
        self.msh, self.tags = geometry.mesh, geometry.facet_tags
        self.V = fem.VectorFunctionSpace(self.msh, ("Lagrange", 1))
        self.Z = fem.FunctionSpace(self.msh, ("Lagrange", 1))
        self.k = args.k
        self.N = int(round((args.T or self.ex.T) / args.k))
        self.t_c = fem.Constant(self.msh, 0.0)
        self.x = ufl.SpatialCoordinate(self.msh)
        self.ds = ufl.Measure("ds", domain=self.msh, subdomain_data=self.tags)
        self.n_f = ufl.FacetNormal(self.msh)

    def const(self, value):
        return fem.Constant(self.msh, float(value))

    def traction(self):
        return self.ex.traction(self.x, self.t_c) if self.ex.traction else None

    def body_force(self):
        return self.ex.body_force(self.x, self.t_c) if self.ex.body_force else None

    def clamped(self, tag):
        facets = self.tags.indices[self.tags.values == tag]
        return fem.dirichletbc(np.zeros(2, dtype=PETSc.ScalarType),
                               fem.locate_dofs_topological(self.V, 1, facets), self.V)

    def normal_zero(self, tag, component):
        """v_component = 0 on the tagged facets (bilateral contact on a straight side)."""
        facets = self.tags.indices[self.tags.values == tag]
        Vc = self.V.sub(component)
        return fem.dirichletbc(PETSc.ScalarType(0.0),
                               fem.locate_dofs_topological(Vc, 1, facets), Vc)


def lu(A):
    ksp = PETSc.KSP().create(comm)
    ksp.setOperators(A)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    return ksp


def assemble_rhs(b, L, a=None, bcs=()):
    """b = assembled L, lifted and with the boundary values of bcs."""
    with b.localForm() as bl:
        bl.set(0.0)
    fpetsc.assemble_vector(b, L)
    if a is not None:
        fpetsc.apply_lifting(b, [a], [list(bcs)])
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    if a is not None:
        fpetsc.set_bc(b, list(bcs))


def obstacle_damage(s, zeta, zeta_old, phi):
    """The damage inclusion step: zeta in [zeta_star, 1] with (zeta - zeta_old, xi - zeta) +
    k kappa (grad zeta, grad(xi - zeta)) >= k (phi, xi - zeta), SNES vinewtonrsls; its matrix is
    constant (assembled once). Returns solve()."""
    Z = zeta.function_space
    a_d, L_d = damage_step_forms(ufl.TrialFunction(Z), ufl.TestFunction(Z), zeta_old, phi,
                                 s.const(s.k), s.const(s.p.kappa))
    F_d = fem.form(ufl.action(a_d, zeta) - L_d)
    A_d = fpetsc.assemble_matrix(fem.form(a_d))
    A_d.assemble()
    b_d = fpetsc.create_vector(F_d)

    def residual(snes, z, f):
        z.copy(zeta.vector)
        zeta.x.scatter_forward()
        assemble_rhs(f, F_d)

    snes = PETSc.SNES().create(comm)
    snes.setOptionsPrefix("damage_")
    PETSc.Options()["damage_snes_linesearch_type"] = "basic"
    snes.setFunction(residual, b_d)
    snes.setJacobian(lambda *a: None, A_d, A_d)
    snes.setType("vinewtonrsls")
    snes.setTolerances(rtol=1e-10, atol=1e-12, stol=0.0, max_it=50)
    snes.setFromOptions()
    snes.getKSP().setType("cg")
    snes.getKSP().getPC().setType("jacobi")
    snes.getKSP().setTolerances(rtol=1e-12, atol=1e-50)
    lower, upper = zeta.vector.duplicate(), zeta.vector.duplicate()
    lower.set(s.p.zeta_star)
    upper.set(1.0)
    snes.setVariableBounds(lower, upper)

    def solve():
        snes.solve(None, zeta.vector)
        if snes.getConvergedReason() <= 0:
            raise SystemExit("damage step did not converge")
        zeta.x.scatter_forward()
    return solve


def tresca_regularised(s, velocity, test, contact_tag):
    """The regularised Tresca term g clip(v_1/eps, -1, 1) w_1 on Gamma_C, integrated at the
    vertices (the tangential direction is x_1; v_2 = 0 there by a boundary condition)."""
    g, e = s.const(s.x_["g_fric"]), s.const(s.x_["eps_reg"])
    ds_nodal = s.ds(contact_tag, metadata={"quadrature_rule": "GLL", "quadrature_degree": 1})
    return g * ufl.max_value(-1.0, ufl.min_value(1.0, velocity[0] / e)) * test[0] * ds_nodal


def newton(F, u, bcs, prefix, rtol=1e-10, atol=1e-10):
    """A plain SNES Newton (newtonls, basic line search, MUMPS LU) on F(u; .) = 0 with its UFL
    Jacobian. Returns solve()."""
    F_form = fem.form(F)
    J_form = fem.form(ufl.derivative(F, u, ufl.TrialFunction(u.function_space)))
    b = fpetsc.create_vector(F_form)
    A = fpetsc.create_matrix(J_form)

    def residual(snes, x, f):
        x.copy(u.vector)
        u.x.scatter_forward()
        with f.localForm() as fl:
            fl.set(0.0)
        fpetsc.assemble_vector(f, F_form)
        fpetsc.apply_lifting(f, [J_form], [bcs], x0=[x], scale=-1.0)
        f.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        fpetsc.set_bc(f, bcs, x, -1.0)

    def jacobian(snes, x, J, P):
        J.zeroEntries()
        fpetsc.assemble_matrix(J, J_form, bcs=bcs)
        J.assemble()

    snes = PETSc.SNES().create(comm)
    snes.setOptionsPrefix(prefix)
    opts = PETSc.Options()
    opts[prefix + "snes_linesearch_type"] = "basic"
    opts[prefix + "snes_divergence_tolerance"] = -1  # a stiff contact's first residual jump
    snes.setFunction(residual, b)
    snes.setJacobian(jacobian, A, A)
    snes.setType("newtonls")
    snes.setTolerances(rtol=rtol, atol=atol, stol=0.0, max_it=100)
    snes.setFromOptions()
    snes.getKSP().setType("preonly")
    snes.getKSP().getPC().setType("lu")
    snes.getKSP().getPC().setFactorSolverType("mumps")

    def solve():
        for bc in bcs:  # the boundary values into the iterate (zero here)
            fpetsc.set_bc(u.vector, [bc])
        snes.solve(None, u.vector)
        if snes.getConvergedReason() <= 0:
            raise SystemExit(f"{prefix[:-1]} Newton did not converge "
                             f"({snes.getConvergedReason()})")
        u.x.scatter_forward()
        return snes.getIterationNumber()
    return solve


class Outputs:
    """fields in fields.xdmf every N/20 steps (and the last), one row of history.csv per step
    (the L2 norms of ``norms`` and min zeta; a non-finite state, or with ``bounded`` a zeta below
    zeta_star, stops the run),
    the final fields in final.npz (serial)."""

    def __init__(self, s, fields, norms, zeta, bounded=True):
        self.s, self.fields, self.zeta = s, fields, zeta
        self.floor = s.p.zeta_star - 1e-6 if bounded else -np.inf
        self.names = list(norms)
        self.forms = [fem.form(ufl.inner(f, f) * ufl.dx) for f in norms.values()]
        self.xdmf = io.XDMFFile(comm, str(s.out / "fields.xdmf"), "w")
        self.xdmf.write_mesh(s.msh)
        self.history = open(s.out / "history.csv", "w") if comm.rank == 0 else None
        if self.history:
            self.history.write(",".join(["step", "t"] + [f"{n}_L2" for n in self.names]
                                        + ["zeta_min"]) + "\n")
        self.every = max(1, s.N // 20)
        self.start = time.perf_counter()

    def step(self, step, force_write=False):
        values = [math.sqrt(comm.allreduce(fem.assemble_scalar(f), op=MPI.SUM))
                  for f in self.forms]
        zmin = comm.allreduce(self.zeta.x.array.min(), op=MPI.MIN)
        if not (np.isfinite(values).all() and zmin >= self.floor):
            raise SystemExit(f"bad state at step {step}")
        t = step * self.s.k
        if self.history:
            self.history.write(",".join([str(step), f"{t:.10g}"]
                                        + [f"{v:.10g}" for v in values + [zmin]]) + "\n")
        if step % self.every == 0 or step == self.s.N or force_write:
            for f in self.fields:
                self.xdmf.write_function(f, t)
        return zmin

    def close(self, u, steps):
        self.xdmf.close()
        if self.history:
            self.history.close()
        if comm.size == 1:
            np.savez(self.s.out / "final.npz", u=u.x.array, zeta=self.zeta.x.array,
                     coords=self.s.Z.tabulate_dof_coordinates())
        if comm.rank == 0:
            print(f"{steps} steps in {time.perf_counter() - self.start:.2f} s")
