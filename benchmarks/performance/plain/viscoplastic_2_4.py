"""2.4 Ex. 1 (P1, Tresca) written the straightforward way, to time the package against: the same
discrete problem (the package's UFL forms, mesh and data), a plain DOLFINx time loop.

    python benchmarks/performance/plain/viscoplastic_2_4.py --n 64 --k 0.002 --out DIR

Per step (2.184)-(2.187): Ghat_n = (1 - zeta_{n-1}) Phi_L(sigma_{n-1}) interpolated into DG0
tensors; the increment w in V (w_2 = 0 on Gamma_C, y = 0) with Tresca friction regularised as
g clip(w_1/eps, -1, 1), eps = eps_reg, vertex rule on Gamma_C, by a plain SNES Newton from
w_{n-1}; u_n = u_{n-1} + k w; sigma_n = sigma_{n-1} + k B eps(w) + k Ghat_n interpolated into
DG0; the damage obstacle step by SNES vinewtonrsls. Outputs: u, zeta in an XDMF file every N/20
steps, ||u||_L2, ||sigma||_L2, min zeta per step in history.csv, the final u, zeta in
final.npz."""
import ufl
from dolfinx import fem

from common import Outputs, Setting, newton, obstacle_damage, tresca_regularised
from damage_dolfinx.forms.viscoplastic import increment_step_forms, stress_update, viscoplastic_rate
from damage_dolfinx.geometries import GAMMA_C, GAMMA_D, GAMMA_N
from damage_dolfinx.models.laws import thesis_law
from damage_dolfinx.forms.constitutive import eps

s = Setting("2.4-ex1", 64, 0.002, "plain_2_4")
p, x_ = s.p, s.x_
Q = fem.TensorFunctionSpace(s.msh, ("DG", 0))
u, u_old, w = (fem.Function(s.V, name=n) for n in ("u", "u_old", "w"))
sigma, sigma_old, G_hat = (fem.Function(Q, name=n) for n in ("sigma", "sigma_old", "G_hat"))
zeta, zeta_old = fem.Function(s.Z, name="zeta"), fem.Function(s.Z)
zeta.x.array[:] = 1.0
k = s.const(s.k)
points = Q.element.interpolation_points()
G_expr = fem.Expression(viscoplastic_rate(sigma_old, zeta_old, p.L_trunc,
                                          x_["viscoplastic_sign"]), points)
sigma_expr = fem.Expression(stress_update(sigma_old, w, G_hat, k, p.E, p.nu), points)

v = ufl.TestFunction(s.V)
a, l = increment_step_forms(w, v, sigma_old, G_hat, k, p.E, p.nu, s.body_force(), s.traction(),
                            s.ds(GAMMA_N))
friction = tresca_regularised(s, w, v, GAMMA_C)
increment = newton(a - l + friction, w, [s.clamped(GAMMA_D), s.normal_zero(GAMMA_C, 1)],
                   "friction_")
damage = obstacle_damage(s, zeta, zeta_old, thesis_law(p.variant)(eps(u_old), zeta_old, p))

out = Outputs(s, (u, zeta), {"u": u, "sigma": sigma}, zeta)
for step in range(1, s.N + 1):
    s.t_c.value = step * s.k
    u_old.x.array[:] = u.x.array
    sigma_old.x.array[:] = sigma.x.array
    zeta_old.x.array[:] = zeta.x.array
    G_hat.interpolate(G_expr)                               # Ghat_n
    increment()                                             # (2.187), from w_{n-1}
    u.x.array[:] = u_old.x.array + s.k * w.x.array          # (2.184)
    sigma.interpolate(sigma_expr)
    damage()                                                # (2.186)
    out.step(step)
out.close(u, s.N)
