"""2.2 Ex. 1 written the straightforward way, to time the package against: the same discrete
problem (the package's UFL forms, mesh and data), a plain DOLFINx time loop.

    python benchmarks/performance/plain/kelvin_voigt_2_2.py --n 64 --k 0.002 --out DIR

Per step: the damage obstacle step (2.66) by SNES vinewtonrsls with bounds [zeta_star, 1]; the
velocity step (2.67), v.nu = 0 on Gamma_C (y = 0, so v_2 = 0 there) and Tresca friction
regularised as Phi_eps(v_1) = g clip(v_1/eps, -1, 1), eps = eps_reg, integrated by the vertex
rule on Gamma_C, solved by a plain SNES Newton from v_{n-1}; u_n = u_{n-1} + k v_n (2.68).
Outputs: u, v, zeta in an XDMF file every N/20 steps, ||u||_L2, ||v||_L2, min zeta per step in
history.csv, the final u, zeta in final.npz."""
import ufl
from dolfinx import fem

from common import Outputs, Setting, newton, obstacle_damage, tresca_regularised
from damage_dolfinx.forms.kelvin_voigt import velocity_step_forms
from damage_dolfinx.geometries import GAMMA_C, GAMMA_D, GAMMA_N
from damage_dolfinx.models.laws import thesis_law
from damage_dolfinx.forms.constitutive import eps

s = Setting("2.2-ex1", 64, 0.002, "plain_2_2")
p, x_ = s.p, s.x_
u, u_old, v = (fem.Function(s.V, name=n) for n in ("u", "u_old", "v"))
zeta, zeta_old = fem.Function(s.Z, name="zeta"), fem.Function(s.Z)
zeta.x.array[:] = 1.0

damage = obstacle_damage(s, zeta, zeta_old, thesis_law(p.variant)(eps(u_old), zeta_old, p))

w = ufl.TestFunction(s.V)
a, l = velocity_step_forms(v, w, u_old, zeta_old, p.E, p.nu, x_["m_visc"], p.L_trunc,
                           s.body_force(), s.traction(), s.ds(GAMMA_N))
friction = tresca_regularised(s, v, w, GAMMA_C)
velocity = newton(a - l + friction, v, [s.clamped(GAMMA_D), s.normal_zero(GAMMA_C, 1)],
                  "friction_")

out = Outputs(s, (u, v, zeta), {"u": u, "v": v}, zeta)
for step in range(1, s.N + 1):
    s.t_c.value = step * s.k
    u_old.x.array[:] = u.x.array
    zeta_old.x.array[:] = zeta.x.array
    damage()                                                # (2.66)
    velocity()                                              # (2.67), from v_{n-1}
    u.x.array[:] = u_old.x.array + s.k * v.x.array          # (2.68)
    out.step(step)
out.close(u, s.N)
