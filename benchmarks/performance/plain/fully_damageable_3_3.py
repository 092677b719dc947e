"""3.3 Ex. 1 written the straightforward way, to time the package against: the same discrete
problem (the package's UFL forms, mesh and data), a plain DOLFINx time loop.

    python benchmarks/performance/plain/fully_damageable_3_3.py --n 64 --k 0.002 --out DIR

Per step (3.158)-(3.160): the damage obstacle step by SNES vinewtonrsls with bounds
[zeta_star, 1]; the velocity step, linear, its matrix (rho/k M + zeta_n A) assembled with the
new damage and LU-factorised (MUMPS) every step; u_n = u_{n-1} + k v_n. Outputs: u, v, zeta in
an XDMF file every N/20 steps, ||u||_L2, ||v||_L2, min zeta per step in history.csv, the final
u, zeta in final.npz."""
import ufl
from dolfinx import fem
from dolfinx.fem import petsc as fpetsc

from common import Outputs, Setting, assemble_rhs, lu, obstacle_damage
from damage_dolfinx.forms.fully_damageable import velocity_step_forms
from damage_dolfinx.geometries import GAMMA_C, GAMMA_D, GAMMA_N
from damage_dolfinx.models.laws import thesis_law
from damage_dolfinx.forms.constitutive import eps

s = Setting("3.3-ex1", 64, 0.002, "plain_3_3")
p, x_ = s.p, s.x_
u, u_old, v, v_old = (fem.Function(s.V, name=n) for n in ("u", "u_old", "v", "v_old"))
zeta, zeta_old = fem.Function(s.Z, name="zeta"), fem.Function(s.Z)
zeta.x.array[:] = 1.0

damage = obstacle_damage(s, zeta, zeta_old, thesis_law(p.variant)(eps(u_old), zeta_old, p))

a, l = velocity_step_forms(ufl.TrialFunction(s.V), ufl.TestFunction(s.V), v_old, u_old, zeta,
                           zeta_old, s.const(x_["rho"]), s.const(s.k), p.E, p.nu,
                           float(x_["m_visc"]), p.L_trunc, p.zeta_star, s.const(x_["c_nu"]),
                           s.const(x_["gap"]), s.n_f, s.body_force(), s.traction(),
                           s.ds(GAMMA_N), s.ds(GAMMA_C))
a, l = fem.form(a), fem.form(l)
bcs = [s.clamped(GAMMA_D)]
A, b = fpetsc.create_matrix(a), fpetsc.create_vector(l)
ksp = lu(A)

out = Outputs(s, (u, v, zeta), {"u": u, "v": v}, zeta)
for step in range(1, s.N + 1):
    s.t_c.value = step * s.k
    u_old.x.array[:] = u.x.array
    v_old.x.array[:] = v.x.array
    zeta_old.x.array[:] = zeta.x.array
    damage()                                                # (3.158)
    A.zeroEntries()                                         # (3.159), with zeta_n
    fpetsc.assemble_matrix(A, a, bcs=bcs)
    A.assemble()
    ksp.setOperators(A)
    assemble_rhs(b, l, a, bcs)
    ksp.solve(b, v.vector)
    v.x.scatter_forward()
    u.x.array[:] = u_old.x.array + s.k * v.x.array          # (3.160)
    out.step(step)
out.close(u, s.N)
