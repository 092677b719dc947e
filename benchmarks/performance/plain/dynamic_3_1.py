"""3.1 Ex. 1 written the straightforward way, to time the package against: the same discrete
problem (the package's UFL forms, mesh and data), a plain DOLFINx time loop.

    python benchmarks/performance/plain/dynamic_3_1.py --n 128 --k 0.005 --out DIR

Per step: the damage obstacle step (3.49) by SNES vinewtonrsls with bounds [zeta_star, 1],
the velocity step (3.48) with its matrix assembled and LU-factorised (MUMPS) once, the right-hand
side assembled per step, u_n = u_{n-1} + k v_n (3.51). Outputs: u, v, zeta in an XDMF file
every N/20 steps, ||u||_L2, ||v||_L2, min zeta per step in history.csv, and the final u, zeta
(final.npz, to compare with the package's fields_final.npz)."""
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
from damage_dolfinx.catalogue.section_3_1 import layout_example1
from damage_dolfinx.forms.damage import damage_step_forms
from damage_dolfinx.forms.dynamic_kelvin_voigt import velocity_step_forms
from damage_dolfinx.geometries import GAMMA_C, GAMMA_D, GAMMA_N
from damage_dolfinx.geometries.rectangle import rectangle
from damage_dolfinx.laws import thesis_law
from damage_dolfinx.numerics.constitutive import eps

ap = argparse.ArgumentParser()
ap.add_argument("--n", type=int, default=128)
ap.add_argument("--k", type=float, default=0.005)
ap.add_argument("--T", type=float, default=1.0)
ap.add_argument("--out", default="plain_3_1")
args = ap.parse_args()
out = Path(args.out)
out.mkdir(parents=True, exist_ok=True)
comm = MPI.COMM_WORLD

ex = examples.get("3.1-ex1")          # the data only: parameters and the traction
p, x_ = ex.params, ex.params.extra
geometry = rectangle(comm, (0, 0), (6, 6), args.n, args.n, layout_example1())
msh, tags = geometry.mesh, geometry.facet_tags
V = fem.VectorFunctionSpace(msh, ("Lagrange", 1))
Z = fem.FunctionSpace(msh, ("Lagrange", 1))
u, u_old, v, v_old = (fem.Function(V, name=s) for s in ("u", "u_old", "v", "v_old"))
zeta, zeta_old = fem.Function(Z, name="zeta"), fem.Function(Z)
zeta.x.array[:] = 1.0
zeta_old.x.array[:] = 1.0
N = int(round(args.T / args.k))
k = args.k
t_c = fem.Constant(msh, 0.0)
const = lambda value: fem.Constant(msh, float(value))  # noqa: E731
ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
n_f = ufl.FacetNormal(msh)
x = ufl.SpatialCoordinate(msh)

# damage step: F(zeta) = a(zeta, xi) - L(xi), bounds [zeta_star, 1]
phi = thesis_law(p.variant)(eps(u_old), zeta_old, p)
zt, xi = ufl.TrialFunction(Z), ufl.TestFunction(Z)
a_d, L_d = damage_step_forms(zt, xi, zeta_old, phi, const(k), const(p.kappa))
F_d = fem.form(ufl.action(a_d, zeta) - L_d)
J_d = fem.form(a_d)
A_d = fpetsc.create_matrix(J_d)
fpetsc.assemble_matrix(A_d, J_d)                   # constant Jacobian: assembled once
A_d.assemble()
b_d = fpetsc.create_vector(F_d)


def residual(snes, z, f):
    z.copy(zeta.vector)
    zeta.x.scatter_forward()
    with f.localForm() as fl:
        fl.set(0.0)
    fpetsc.assemble_vector(f, F_d)
    f.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)


snes = PETSc.SNES().create(comm)
snes.setFunction(residual, b_d)
snes.setJacobian(lambda *a: None, A_d, A_d)
snes.setType("vinewtonrsls")
snes.setTolerances(rtol=1e-10, atol=1e-12, stol=0.0, max_it=50)
opts = PETSc.Options()
opts["damage_snes_linesearch_type"] = "basic"
snes.setOptionsPrefix("damage_")
snes.setFromOptions()
snes.getKSP().setType("cg")
snes.getKSP().getPC().setType("jacobi")
snes.getKSP().setTolerances(rtol=1e-12, atol=1e-50)
lower, upper = zeta.vector.duplicate(), zeta.vector.duplicate()
lower.set(p.zeta_star)
upper.set(1.0)
snes.setVariableBounds(lower, upper)

# velocity step: constant matrix, LU once
a_v, l_v = velocity_step_forms(ufl.TrialFunction(V), ufl.TestFunction(V), v_old, u_old, zeta_old,
                               const(x_["rho"]), const(k), p.E, p.nu, x_["m_visc"], p.L_trunc,
                               const(x_["c_nu"]), const(x_["gap"]), n_f, None,
                               ex.traction(x, t_c), ds(GAMMA_N), ds(GAMMA_C))
a_v, l_v = fem.form(a_v), fem.form(l_v)
facets = tags.indices[tags.values == GAMMA_D]
bc = fem.dirichletbc(np.zeros(2, dtype=PETSc.ScalarType),
                     fem.locate_dofs_topological(V, 1, facets), V)
A_v = fpetsc.assemble_matrix(a_v, bcs=[bc])
A_v.assemble()
b_v = fpetsc.create_vector(l_v)
ksp = PETSc.KSP().create(comm)
ksp.setOperators(A_v)
ksp.setType("preonly")
ksp.getPC().setType("lu")
ksp.getPC().setFactorSolverType("mumps")

# outputs
norms = [fem.form(ufl.inner(u, u) * ufl.dx), fem.form(ufl.inner(v, v) * ufl.dx)]
xdmf = io.XDMFFile(comm, str(out / "fields.xdmf"), "w")
xdmf.write_mesh(msh)
history = open(out / "history.csv", "w") if comm.rank == 0 else None
if history:
    history.write("step,t,u_L2,v_L2,zeta_min\n")
write_every = max(1, N // 20)
start = time.perf_counter()
for step in range(1, N + 1):
    t_c.value = step * k
    u_old.x.array[:] = u.x.array
    v_old.x.array[:] = v.x.array
    zeta_old.x.array[:] = zeta.x.array
    snes.solve(None, zeta.vector)                           # (3.49)
    assert snes.getConvergedReason() > 0, "damage step did not converge"
    zeta.x.scatter_forward()
    with b_v.localForm() as bl:                             # (3.48)
        bl.set(0.0)
    fpetsc.assemble_vector(b_v, l_v)
    fpetsc.apply_lifting(b_v, [a_v], [[bc]])
    b_v.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    fpetsc.set_bc(b_v, [bc])
    ksp.solve(b_v, v.vector)
    v.x.scatter_forward()
    u.x.array[:] = u_old.x.array + k * v.x.array            # (3.51)
    s = [math.sqrt(comm.allreduce(fem.assemble_scalar(f), op=MPI.SUM)) for f in norms]
    zmin = comm.allreduce(zeta.x.array.min(), op=MPI.MIN)
    if not (np.isfinite(s).all() and zmin >= p.zeta_star - 1e-6):
        raise SystemExit(f"bad state at step {step}")
    if history:
        history.write(f"{step},{step * k:.10g},{s[0]:.10g},{s[1]:.10g},{zmin:.10g}\n")
    if step % write_every == 0 or step == N:
        for f in (u, v, zeta):
            xdmf.write_function(f, step * k)
xdmf.close()
if history:
    history.close()
if comm.size == 1:
    np.savez(out / "final.npz", u=u.x.array, zeta=zeta.x.array,
             coords=Z.tabulate_dof_coordinates())
if comm.rank == 0:
    print(f"{N} steps in {time.perf_counter() - start:.2f} s")
