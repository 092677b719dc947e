"""3-D contact: normal compliance on a plane face against its closed form, the 3-D
contact monitor, the wrench plate's facet tags against the outline times the thickness, and
serial = 2 ranks for the 3-D contact examples (2.3-ex1-3d, 3.1-ex1-3d, 3.3-ex1-3d, 3.3-ex3-3d)
at tiny meshes. Every test takes seconds."""
import math

import numpy as np
import pytest
import ufl
from dolfinx import fem
from mpi4py import MPI

from damage_dolfinx import compat
from damage_dolfinx.geometries import GAMMA_C, GAMMA_D, GAMMA_N

#: facets on rollers (u.nu = 0) in the closed-form test
ROLLER = 7


def _block(n, comm=MPI.COMM_WORLD):
    """Unit cube: rollers on x = 0 and y = 0, foundation (Gamma_C) below, load on top."""
    from damage_dolfinx.geometries.box import box, face
    return box(comm, (0.0, 0.0, 0.0), (1.0, 1.0, 1.0), (n, n, n), {
        ROLLER: lambda x: face(0, 0.0)(x) | face(1, 0.0)(x), GAMMA_C: face(2, 0.0),
        GAMMA_N: face(2, 1.0)})


def test_block_on_normal_compliance_foundation_closed_form():
    """A block pressed by a uniform pressure p onto a normal-compliance foundation
    (normal compliance: -sigma_nu = c_nu (u.nu - gap)_+), frictionless, on rollers at x = 0 and
    y = 0, free at x = 1, y = 1: uniaxial stress sigma_zz = -p, so the foundation is pressed in
    uniformly by u.nu = p/c_nu and u = (nu p x/E, nu p y/E, -p/c_nu - p z/E), linear, which P1
    reproduces to round-off. Solved with the 2.3 residual (2.137, no memory) and the package's
    semismooth Newton; checked at every node and by the 3-D contact monitor of 3.3."""
    from damage_dolfinx.numerics.boundary import bilateral_plane_faces
    from damage_dolfinx.forms.viscoelastic_memory import displacement_residual
    from damage_dolfinx.models.monitors import ContactMonitor
    from damage_dolfinx.numerics.solvers import NonlinearSolver, SolveContext

    E, nu, c_nu, p = 100.0, 0.3, 1e4, 10.0
    geometry = _block(3)
    msh, tags = geometry.mesh, geometry.facet_tags
    V = compat.vector_p1(msh)
    u = fem.Function(V)
    M = fem.Function(compat.tensor_dg0(msh))  # no memory: M = 0
    ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
    n = ufl.FacetNormal(msh)
    F = displacement_residual(u, ufl.TestFunction(V), M, E, nu, c_nu, 0.0, n, None,
                              ufl.as_vector((0.0, 0.0, -p)), ds(GAMMA_N), ds(GAMMA_C))
    solver = NonlinearSolver(F, u, bilateral_plane_faces(V, tags, ROLLER), "cb3d_",
                             SolveContext(example="closed form"))
    u.x.array.reshape(-1, 3)[:, 2] = -1e-8  # start in contact (p_nu'(0) = 0: z-shift free)
    its = solver.solve()
    x = V.tabulate_dof_coordinates()
    exact = np.stack([nu * p * x[:, 0] / E, nu * p * x[:, 1] / E,
                      -p / c_nu - p * x[:, 2] / E], axis=1)
    err = np.abs(u.x.array.reshape(-1, 3) - exact).max()
    err = msh.comm.allreduce(err, op=MPI.MAX)
    monitor = ContactMonitor(V, tags, GAMMA_C, 0.0)(u, 1.0)
    area = compat.assemble_scalar(fem.Constant(msh, 1.0) * ds(GAMMA_C), msh.comm)
    force = compat.assemble_scalar(c_nu * ufl.max_value(ufl.dot(u, n), 0.0) * ds(GAMMA_C),
                                   msh.comm)
    if msh.comm.rank == 0:
        print(f"Newton its {its}; max nodal error {err:.2e} (|u| ~ {p / E:.2f}); penetration "
              f"{monitor['penetration_max']:.12e} vs p/c_nu = {p / c_nu:.12e}; contact force "
              f"{force:.12f} vs p area = {p * area:.12f}")
    assert err < 1e-12
    assert monitor["penetration_max"] == pytest.approx(p / c_nu, rel=1e-10)
    assert abs(monitor["penetration_x3"]) < 1e-12  # on the foundation face z = 0
    assert force == pytest.approx(p * area, rel=1e-10) and area == pytest.approx(1.0, rel=1e-12)


def test_contact_monitor_normals_on_3d_facets():
    """The 3-D contact monitor: each Gamma_C triangle's normal is the outward unit normal of
    its face (bottom of the cube: (0, 0, -1)), so a downward rigid shift d is a penetration d
    at every vertex, an upward one none."""
    from damage_dolfinx.models.monitors import ContactMonitor
    geometry = _block(2)
    V = compat.vector_p1(geometry.mesh)
    monitor = ContactMonitor(V, geometry.facet_tags, GAMMA_C, 0.0)
    owned = monitor.normal.shape[0]
    if owned:
        assert np.allclose(monitor.normal, [0.0, 0.0, -1.0], atol=1e-14)
    assert monitor.columns == ["penetration_max", "penetration_x1", "penetration_x2",
                               "penetration_x3"]
    u = fem.Function(V)
    u.x.array.reshape(-1, 3)[:, 2] = -0.25
    assert monitor(u, 0.0)["penetration_max"] == pytest.approx(0.25, rel=1e-14)
    u.x.array.reshape(-1, 3)[:, 2] = 0.25
    assert monitor(u, 0.0)["penetration_max"] == 0.0


def test_wrench_plate_tags_match_outline_times_thickness():
    """geometries/wrench_plate.py: Gamma_C = the hexagon's perimeter 6 a/sqrt(3) times the
    thickness (exact: plane faces), Gamma_N = the loaded length 1 times the thickness, with the
    outward normal (1, 1, 0)/sqrt(2), no Gamma_D; the volume and the free faces (two plate faces
    + the rest of the outline times the thickness) against the exact outline, up to gmsh's
    polygonal arcs (h = 0.3: below 1 %)."""
    from damage_dolfinx.geometries.wrench_plate import FREE, wrench_plate
    t, a, R, w2 = 0.4, 1.0, 1.2, 0.4
    geometry = wrench_plate(MPI.COMM_WORLD, h=0.3, h_contact=0.15, thickness=t)
    msh, tags = geometry.mesh, geometry.facet_tags
    ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
    one, n = fem.Constant(msh, 1.0), ufl.FacetNormal(msh)

    def integral(form):
        return compat.assemble_scalar(form, msh.comm)

    # the exact outline: disc + handle outside it - hexagon
    # handle outside the disc: int_{-w2}^{w2} (10 - sqrt(R^2 - y^2)) dy
    handle = 20.0 * w2 - (w2 * math.sqrt(R ** 2 - w2 ** 2) + R ** 2 * math.asin(w2 / R))
    area = math.pi * R ** 2 + handle - math.sqrt(3) / 2 * a ** 2
    arc = 2 * R * (math.pi - math.asin(w2 / R))           # head circle outside the handle
    outline = arc + 2 * (10.0 - math.sqrt(R ** 2 - w2 ** 2)) + 2 * w2  # + handle sides + end
    hexagon = 6 * a / math.sqrt(3)
    found = {name: integral(one * ds(tag)) for name, tag in
             (("C", GAMMA_C), ("N", GAMMA_N), ("D", GAMMA_D), ("free", FREE))}
    volume = integral(one * ufl.dx(domain=msh))
    normal_N = [integral(n[i] * ds(GAMMA_N)) for i in range(3)]
    normal_C = [integral(abs(n[i]) * ds(GAMMA_C)) for i in range(3)]
    if msh.comm.rank == 0:
        print(f"areas {found}, volume {volume:.6f} (exact {area * t:.6f}); free exact "
              f"{2 * area + (outline - 1.0) * t:.6f}")
    assert found["C"] == pytest.approx(hexagon * t, rel=1e-12)
    assert found["N"] == pytest.approx(1.0 * t, rel=1e-12)
    assert found["D"] == 0.0
    assert np.allclose(normal_N, [t / math.sqrt(2), t / math.sqrt(2), 0.0], rtol=1e-12,
                       atol=1e-12)
    assert normal_C[2] < 1e-12  # the hexagon faces are vertical
    assert volume == pytest.approx(area * t, rel=1e-2)
    assert found["free"] == pytest.approx(2 * area + (outline - 1.0) * t, rel=1e-2)


CASES = {
    # 2.3 at n = 10: 3993 unknowns, Newton with CG + GAMG (rigid-body modes)
    "2.3-ex1-3d": ["--n", "10", "--T", "0.03"],
    # 3.1 at n = 10: velocity CG + GAMG; the explicit contact force stays stable at k = 0.01
    "3.1-ex1-3d": ["--n", "10", "--T", "0.05", "--set", "stability_check=off"],
    "3.3-ex1-3d": ["--n", "4", "--T", "0.05"],
    # the wrench plate, coarse: serial takes the fast matrix update, 2 ranks the assembly
    "3.3-ex3-3d": ["--h", "0.4", "--T", "0.0001"],
}


@pytest.mark.mpi
@pytest.mark.parametrize("example", list(CASES))
def test_contact_3d_serial_equals_two_ranks(tmp_path, example):
    """Each 3-D contact example at a tiny mesh: the same final fields and contact scalars on 1
    and 2 ranks to the solver tolerance."""
    from conftest import serial_and_two_ranks
    (s_sum, _), (p_sum, _) = serial_and_two_ranks(
        tmp_path, ["run", example, *CASES[example], "--quiet", "--no-figures"], tol=1e-8)
    assert s_sum["status"] == p_sum["status"] == "completed"
    for key, value in s_sum["final"].items():
        if key.startswith("penetration_x"):  # the location of a maximum of round-off size
            continue
        scale = max(abs(value), 1e-12 if "penetration" in key else 1e-300)
        assert abs(p_sum["final"][key] - value) <= 1e-7 * scale, key


@pytest.mark.parametrize("n", [3, 10])
def test_dynamic_block_contact_force_balance(n):
    """3.1 in 3-D: a free block (no Gamma_D) pushed by a pressure p onto the foundation. With
    the constant test function w = e_z (in V: Gamma_D is empty) the velocity step (3.48) is the
    discrete momentum balance rho (P_n - P_{n-1})/k = -p A_N + int_{Gamma_C} c_nu
    (u_{n-1}.nu)_+ ds (viscous and elastic forces of a rigid w vanish; nu_z = -1 on the bottom),
    P = int v_z dx: it must hold at every step to the solver tolerance, as must the zero x- and
    y-momentum. n = 3: factorised velocity matrix; n = 10 (3993 unknowns): CG + GAMG."""
    from damage_dolfinx.geometries.box import box, face
    from damage_dolfinx.core.parameters import ModelParameters
    from damage_dolfinx.problem.problem import Problem
    from damage_dolfinx.models.dynamic_3_1 import DynamicKelvinVoigt
    p, rho, c_nu, k = 20.0, 1.0, 2e4, 0.01
    geometry = box(MPI.COMM_WORLD, (0.0, 0.0, 0.0), (1.0, 1.0, 1.0), (n, n, n),
                   {GAMMA_C: face(2, 0.0), GAMMA_N: face(2, 1.0)})
    params = ModelParameters(E=1000.0, nu=0.3, kappa=1.0, variant="A", lam_D=1e-2, lam_u=1e3,
                             q_star=1.0, L_trunc=1000.0, stop_at_zeta_star=False,
                             extra={"rho": rho, "m_visc": 10.0, "c_nu": c_nu, "gap": 0.0,
                                    "damage_active": False, "stability_check": "off"})
    data = Problem("3.1", geometry, 0.3, k=k, params=params.validate(), name="block",
                       traction=lambda x, t: ufl.as_vector((0.0, 0.0, -p)))
    st = DynamicKelvinVoigt(data)
    msh = st.mesh
    ds = ufl.Measure("ds", domain=msh, subdomain_data=geometry.facet_tags)
    momentum = [compat.form(rho * st.v[i] * ufl.dx) for i in range(3)]
    contact = compat.form(c_nu * ufl.max_value(ufl.dot(st.u, st.n_facet), 0.0) * ds(GAMMA_C))
    area_N = compat.assemble_scalar(fem.Constant(msh, 1.0) * ds(GAMMA_N), msh.comm)
    st.initialize()
    worst, lateral, forces = 0.0, 0.0, []
    for _ in range(st.num_steps):
        P_old = compat.assemble_scalar(momentum[2], msh.comm)
        F_c = compat.assemble_scalar(contact, msh.comm)  # at u_{n-1}
        st.advance()
        P = [compat.assemble_scalar(m, msh.comm) for m in momentum]
        balance = -p * area_N + F_c
        worst = max(worst, abs((P[2] - P_old) / k - balance) / (p * area_N))
        lateral = max(lateral, abs(P[0]) + abs(P[1]))
        forces.append(F_c)
    if msh.comm.rank == 0:
        print(f"n = {n}: momentum balance worst relative residual {worst:.2e}, lateral momentum "
              f"{lateral:.2e}, contact force at the last steps {forces[-3:]} (p A = {p})")
    assert max(forces) > 0.5 * p  # the foundation carries the block
    assert worst < 1e-8
    assert lateral < 1e-10 * p
