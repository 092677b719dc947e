"""2.1 Ex. 1 written the straightforward way, to time the package against: the same discrete
problem (the package's UFL forms, mesh and data), a plain DOLFINx time loop.

    python benchmarks/performance/plain/elastic_2_1.py --n 160 --k 0.01 --out DIR

Per step: the damage step (2.20) (M + k kappa K) zeta_n = M zeta_{n-1} + k (phi(eps(u_{n-1}),
zeta_{n-1}), .), its constant matrix LU-factorised (MUMPS) once; the equilibrium (2.21) with the
new damage, its matrix assembled and LU-factorised every step. The run stops when min zeta_n
<= zeta_star, as the package's does. Outputs: u, zeta in an XDMF file every N/20 steps,
||u||_L2 and min zeta per step in history.csv, the final u, zeta in final.npz."""
import ufl
from dolfinx import fem
from dolfinx.fem import petsc as fpetsc
from mpi4py import MPI

from common import Outputs, Setting, assemble_rhs, lu
from damage_dolfinx.forms.damage import damage_step_forms
from damage_dolfinx.forms.elastic_damage import equilibrium_forms
from damage_dolfinx.geometries import GAMMA_D, GAMMA_N
from damage_dolfinx.models.laws import thesis_law
from damage_dolfinx.forms.constitutive import eps

s = Setting("2.1-ex1", 160, 0.01, "plain_2_1")
p = s.p
u = fem.Function(s.V, name="u")
zeta, zeta_old = fem.Function(s.Z, name="zeta"), fem.Function(s.Z)
zeta.x.array[:] = 1.0

# damage step: constant matrix, LU once
phi = thesis_law(p.variant)(eps(u), zeta_old, p)
a_d, L_d = damage_step_forms(ufl.TrialFunction(s.Z), ufl.TestFunction(s.Z), zeta_old, phi,
                             s.const(s.k), s.const(p.kappa))
a_d, L_d = fem.form(a_d), fem.form(L_d)
A_d = fpetsc.assemble_matrix(a_d)
A_d.assemble()
ksp_d, b_d = lu(A_d), fpetsc.create_vector(L_d)

# equilibrium: matrix with the new damage, assembled and factorised every step
a_u, L_u = equilibrium_forms(ufl.TrialFunction(s.V), ufl.TestFunction(s.V), zeta, p.E, p.nu,
                             p.zeta_star, s.body_force(), s.traction(), s.ds(GAMMA_N))
a_u, L_u = fem.form(a_u), fem.form(L_u)
bcs = [s.clamped(GAMMA_D)]
A_u, b_u = fpetsc.create_matrix(a_u), fpetsc.create_vector(L_u)
ksp_u = lu(A_u)


def solve_u():
    A_u.zeroEntries()
    fpetsc.assemble_matrix(A_u, a_u, bcs=bcs)
    A_u.assemble()
    ksp_u.setOperators(A_u)
    assemble_rhs(b_u, L_u, a_u, bcs)
    ksp_u.solve(b_u, u.vector)
    u.x.scatter_forward()


out = Outputs(s, (u, zeta), {"u": u}, zeta, bounded=False)
solve_u()                                                   # t = 0
for step in range(1, s.N + 1):
    s.t_c.value = step * s.k
    zeta_old.x.array[:] = zeta.x.array
    assemble_rhs(b_d, L_d)                                  # (2.20), u = u_{n-1}
    ksp_d.solve(b_d, zeta.vector)
    zeta.x.scatter_forward()
    solve_u()                                               # (2.21)
    zmin = s.msh.comm.allreduce(zeta.x.array.min(), op=MPI.MIN)
    out.step(step, force_write=zmin <= p.zeta_star)
    if zmin <= p.zeta_star:
        break
out.close(u, step)
