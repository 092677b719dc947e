"""2.1 Ex. 1 written the straightforward way, to time the package against: the same discrete
problem (the package's UFL forms, mesh and data), a plain DOLFINx time loop.

    python benchmarks/performance/plain/elastic_2_1.py --n 160 --k 0.01 --out DIR

Per step: the damage step (2.20) (M + k kappa K) zeta_n = M zeta_{n-1} + k (phi(eps(u_{n-1}),
zeta_{n-1}), .), its constant matrix LU-factorised (MUMPS) once; the equilibrium (2.21) with the
new damage, its matrix assembled and LU-factorised every step. The run stops when min zeta_n
<= zeta_star, as the package's does. Outputs: u, zeta in an XDMF file every N/20 steps,
||u||_L2 and min zeta per step in history.csv, the final u, zeta in final.npz."""
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
from damage_dolfinx.forms.elastic_damage import equilibrium_forms
from damage_dolfinx.geometries import GAMMA_D, GAMMA_N
from damage_dolfinx.geometries.square_with_hole import square_with_hole
from damage_dolfinx.laws import thesis_law
from damage_dolfinx.numerics.constitutive import eps

ap = argparse.ArgumentParser()
ap.add_argument("--n", type=int, default=160)
ap.add_argument("--k", type=float, default=0.01)
ap.add_argument("--T", type=float, default=1.0)
ap.add_argument("--out", default="plain_2_1")
args = ap.parse_args()
out = Path(args.out)
out.mkdir(parents=True, exist_ok=True)
comm = MPI.COMM_WORLD

ex = examples.get("2.1-ex1")          # the data only: parameters and the body force
p = ex.params
geometry = square_with_hole(comm, args.n)
msh, tags = geometry.mesh, geometry.facet_tags
V = fem.VectorFunctionSpace(msh, ("Lagrange", 1))
Z = fem.FunctionSpace(msh, ("Lagrange", 1))
u = fem.Function(V, name="u")
zeta, zeta_old = fem.Function(Z, name="zeta"), fem.Function(Z)
zeta.x.array[:] = 1.0
N = int(round(args.T / args.k))
k = args.k
t_c = fem.Constant(msh, 0.0)
x = ufl.SpatialCoordinate(msh)


def lu(A):
    ksp = PETSc.KSP().create(comm)
    ksp.setOperators(A)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    return ksp


# damage step: constant matrix, LU once
phi = thesis_law(p.variant)(eps(u), zeta_old, p)
a_d, L_d = damage_step_forms(ufl.TrialFunction(Z), ufl.TestFunction(Z), zeta_old, phi,
                             fem.Constant(msh, k), fem.Constant(msh, float(p.kappa)))
a_d, L_d = fem.form(a_d), fem.form(L_d)
A_d = fpetsc.assemble_matrix(a_d)
A_d.assemble()
ksp_d = lu(A_d)
b_d = fpetsc.create_vector(L_d)

# equilibrium: matrix with the new damage, assembled and factorised every step
ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
a_u, L_u = equilibrium_forms(ufl.TrialFunction(V), ufl.TestFunction(V), zeta, p.E, p.nu,
                             p.zeta_star, ex.body_force(x, t_c), None, ds(GAMMA_N))
a_u, L_u = fem.form(a_u), fem.form(L_u)
bc = fem.dirichletbc(np.zeros(2, dtype=PETSc.ScalarType),
                     fem.locate_dofs_topological(V, 1, tags.indices[tags.values == GAMMA_D]), V)
A_u = fpetsc.create_matrix(a_u)
b_u = fpetsc.create_vector(L_u)
ksp_u = lu(A_u)


def solve_u():
    A_u.zeroEntries()
    fpetsc.assemble_matrix(A_u, a_u, bcs=[bc])
    A_u.assemble()
    ksp_u.setOperators(A_u)
    with b_u.localForm() as bl:
        bl.set(0.0)
    fpetsc.assemble_vector(b_u, L_u)
    fpetsc.apply_lifting(b_u, [a_u], [[bc]])
    b_u.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    fpetsc.set_bc(b_u, [bc])
    ksp_u.solve(b_u, u.vector)
    u.x.scatter_forward()


norm_u = fem.form(ufl.inner(u, u) * ufl.dx)
xdmf = io.XDMFFile(comm, str(out / "fields.xdmf"), "w")
xdmf.write_mesh(msh)
history = open(out / "history.csv", "w") if comm.rank == 0 else None
if history:
    history.write("step,t,u_L2,zeta_min\n")
write_every = max(1, N // 20)
start = time.perf_counter()
solve_u()                                                   # t = 0
for step in range(1, N + 1):
    t_c.value = step * k
    zeta_old.x.array[:] = zeta.x.array
    with b_d.localForm() as bl:                             # (2.20), u = u_{n-1}
        bl.set(0.0)
    fpetsc.assemble_vector(b_d, L_d)
    b_d.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    ksp_d.solve(b_d, zeta.vector)
    zeta.x.scatter_forward()
    solve_u()                                               # (2.21)
    u_L2 = math.sqrt(comm.allreduce(fem.assemble_scalar(norm_u), op=MPI.SUM))
    zmin = comm.allreduce(zeta.x.array.min(), op=MPI.MIN)
    if not np.isfinite(u_L2):
        raise SystemExit(f"bad state at step {step}")
    if history:
        history.write(f"{step},{step * k:.10g},{u_L2:.10g},{zmin:.10g}\n")
    stop = zmin <= p.zeta_star
    if step % write_every == 0 or step == N or stop:
        for f in (u, zeta):
            xdmf.write_function(f, step * k)
    if stop:
        break
xdmf.close()
if history:
    history.close()
if comm.size == 1:
    np.savez(out / "final.npz", u=u.x.array, zeta=zeta.x.array,
             coords=Z.tabulate_dof_coordinates())
if comm.rank == 0:
    print(f"{step} steps in {time.perf_counter() - start:.2f} s")
