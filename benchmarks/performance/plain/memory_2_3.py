"""2.3 Ex. 1 written the straightforward way, to time the package against: the same discrete
problem (the package's UFL forms, mesh and data), a plain DOLFINx time loop.

    python benchmarks/performance/plain/memory_2_3.py --n 64 --k 0.002 --out DIR

u_0 from the contact problem at t = 0 without memory. Per step (2.136)-(2.137): the memory
M_n = M_{n-1} + k g(u_{n-1}, zeta_{n-1}), g = zeta Phi_L(B eps(u)) interpolated into DG1 tensors
(constant kernel); the damage PDE step (M + k kappa K) zeta_n = M zeta_{n-1} + k (phi, .), its
matrix LU-factorised (MUMPS) once; the displacement step with normal compliance
c_nu (u.nu - gap)_+ on Gamma_C by a plain SNES Newton from u_{n-1}. Outputs: u, zeta in an
XDMF file every N/20 steps, ||u||_L2, min zeta per step in history.csv, the final u, zeta in
final.npz."""
import ufl
from dolfinx import fem
from dolfinx.fem import petsc as fpetsc

from common import Outputs, Setting, assemble_rhs, lu, newton
from damage_dolfinx.forms.damage import damage_step_forms
from damage_dolfinx.forms.viscoelastic_memory import displacement_residual, memory_integrand
from damage_dolfinx.geometries import GAMMA_C, GAMMA_D, GAMMA_N
from damage_dolfinx.models.laws import thesis_law
from damage_dolfinx.forms.constitutive import eps

s = Setting("2.3-ex1", 64, 0.002, "plain_2_3")
p, x_ = s.p, s.x_
assert x_["memory_kernel"] == "constant"
M_space = fem.TensorFunctionSpace(s.msh, ("DG", 1))
u = fem.Function(s.V, name="u")
M, g = fem.Function(M_space, name="memory"), fem.Function(M_space)
zeta, zeta_old = fem.Function(s.Z, name="zeta"), fem.Function(s.Z)
zeta.x.array[:] = 1.0
g_expr = fem.Expression(memory_integrand(u, zeta, p.E, p.nu, p.L_trunc),
                        M_space.element.interpolation_points())

# damage PDE step: constant matrix, LU once
phi = thesis_law(p.variant)(eps(u), zeta_old, p)
a_d, L_d = damage_step_forms(ufl.TrialFunction(s.Z), ufl.TestFunction(s.Z), zeta_old, phi,
                             s.const(s.k), s.const(p.kappa))
a_d, L_d = fem.form(a_d), fem.form(L_d)
A_d = fpetsc.assemble_matrix(a_d)
A_d.assemble()
ksp_d, b_d = lu(A_d), fpetsc.create_vector(L_d)

# displacement step: normal compliance, Newton
F = displacement_residual(u, ufl.TestFunction(s.V), M, p.E, p.nu, float(x_["c_nu"]),
                          float(x_["gap"]), s.n_f, s.body_force(), s.traction(), s.ds(GAMMA_N),
                          s.ds(GAMMA_C))
mech = newton(F, u, [s.clamped(GAMMA_D)], "mech_")

out = Outputs(s, (u, zeta), {"u": u}, zeta)
mech()                                                      # u_0, no memory
amplitude = float(x_["memory_amplitude"])
for step in range(1, s.N + 1):
    s.t_c.value = step * s.k
    g.interpolate(g_expr)                                   # g_{n-1}
    M.x.array[:] += s.k * amplitude * g.x.array             # (2.136)
    zeta_old.x.array[:] = zeta.x.array
    assemble_rhs(b_d, L_d)                                  # damage PDE, u = u_{n-1}
    ksp_d.solve(b_d, zeta.vector)
    zeta.x.scatter_forward()
    mech()                                                  # (2.137), from u_{n-1}
    out.step(step)
out.close(u, s.N)
