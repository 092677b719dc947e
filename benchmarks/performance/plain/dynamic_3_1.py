"""3.1 Ex. 1 written the straightforward way, to time the package against: the same discrete
problem (the package's UFL forms, mesh and data), a plain DOLFINx time loop.

    python benchmarks/performance/plain/dynamic_3_1.py --n 128 --k 0.005 --out DIR

Per step: the damage obstacle step (3.49) by SNES vinewtonrsls with bounds [zeta_star, 1],
the velocity step (3.48) with its matrix assembled and LU-factorised (MUMPS) once, the right-hand
side assembled per step, u_n = u_{n-1} + k v_n (3.51). Outputs: u, v, zeta in an XDMF file
every N/20 steps, ||u||_L2, ||v||_L2, min zeta per step in history.csv, and the final u, zeta
(final.npz, to compare with the package's fields_final.npz)."""
import ufl
from dolfinx import fem
from dolfinx.fem import petsc as fpetsc

from common import Outputs, Setting, assemble_rhs, lu, obstacle_damage
from damage_dolfinx.forms.dynamic_kelvin_voigt import velocity_step_forms
from damage_dolfinx.geometries import GAMMA_C, GAMMA_D, GAMMA_N
from damage_dolfinx.models.laws import thesis_law
from damage_dolfinx.forms.constitutive import eps

s = Setting("3.1-ex1", 128, 0.005, "plain_3_1")
p, x_ = s.p, s.x_
u, u_old, v, v_old = (fem.Function(s.V, name=n) for n in ("u", "u_old", "v", "v_old"))
zeta, zeta_old = fem.Function(s.Z, name="zeta"), fem.Function(s.Z)
zeta.x.array[:] = 1.0

damage = obstacle_damage(s, zeta, zeta_old, thesis_law(p.variant)(eps(u_old), zeta_old, p))

# velocity step: constant matrix, LU once
a_v, l_v = velocity_step_forms(ufl.TrialFunction(s.V), ufl.TestFunction(s.V), v_old, u_old,
                               zeta_old, s.const(x_["rho"]), s.const(s.k), p.E, p.nu,
                               x_["m_visc"], p.L_trunc, s.const(x_["c_nu"]), s.const(x_["gap"]),
                               s.n_f, s.body_force(), s.traction(), s.ds(GAMMA_N), s.ds(GAMMA_C))
a_v, l_v = fem.form(a_v), fem.form(l_v)
bcs = [s.clamped(GAMMA_D)]
A_v = fpetsc.assemble_matrix(a_v, bcs=bcs)
A_v.assemble()
ksp, b_v = lu(A_v), fpetsc.create_vector(l_v)

out = Outputs(s, (u, v, zeta), {"u": u, "v": v}, zeta)
for step in range(1, s.N + 1):
    s.t_c.value = step * s.k
    u_old.x.array[:] = u.x.array
    v_old.x.array[:] = v.x.array
    zeta_old.x.array[:] = zeta.x.array
    damage()                                                # (3.49)
    assemble_rhs(b_v, l_v, a_v, bcs)                        # (3.48)
    ksp.solve(b_v, v.vector)
    v.x.scatter_forward()
    u.x.array[:] = u_old.x.array + s.k * v.x.array          # (3.51)
    out.step(step)
out.close(u, s.N)
