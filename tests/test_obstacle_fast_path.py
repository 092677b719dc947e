"""The fast path of the damage obstacle step (damage_dolfinx/obstacle.py) against SNES
vinewtonrsls alone (-<prefix>vi_fast 0): no active node, nodes held at zeta_star, an active set
that changes within the step (the SNES takes over), and a run in which zeta reaches zeta_star,
serially and on 2 ranks."""
import numpy as np
import pytest
import ufl
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from conftest import load_run, rel_diff, run_cli
from damage_dolfinx import compat
from damage_dolfinx.numerics.damage import DamageStep
from damage_dolfinx.numerics.solvers import SolveContext

ZETA_STAR, K, KAPPA = 0.01, 0.05, 0.05


def _pair(msh, zeta0, phi, name, solver="auto"):
    """(fast, snes-only) DamageSteps of the same problem; zeta_old = zeta0(x)."""
    Z = compat.scalar_p1(msh)
    steps = []
    for prefix in (f"{name}fast_", f"{name}snes_"):
        if prefix.endswith("snes_"):
            PETSc.Options()[prefix + "vi_fast"] = "0"
        else:
            PETSc.Options()[prefix + "vi_fast_solver"] = solver
        zeta, zeta_old = fem.Function(Z), fem.Function(Z)
        zeta_old.interpolate(zeta0)
        steps.append(DamageStep(zeta, zeta_old, phi, fem.Constant(msh, K),
                                fem.Constant(msh, KAPPA), SolveContext(name), obstacle=True,
                                zeta_star=ZETA_STAR, prefix=prefix))
    assert steps[0].fast is not None and steps[1].fast is None
    return steps


def _owned(step):
    return step.zeta.x.array[:step.zeta.function_space.dofmap.index_map.size_local]


def _max_diff(a, b, comm):
    return comm.allreduce(float(np.max(np.abs(_owned(a) - _owned(b)), initial=0.0)), op=MPI.MAX)


def _count(step, predicate, comm):
    return comm.allreduce(int(np.sum(predicate(_owned(step)))), op=MPI.SUM)


def test_no_active_node_one_factorisation_reused(unit_square):
    msh = unit_square(16)
    x = ufl.SpatialCoordinate(msh)
    phi = 2.0 * ufl.sin(2 * np.pi * x[0]) * ufl.cos(np.pi * x[1])
    fast, snes = _pair(msh, lambda X: 0.5 + 0.2 * np.sin(3 * X[0]) * np.cos(2 * X[1]), phi, "na")
    for n in range(3):  # three steps: the reduced solver (here the full B) is built once
        assert fast.solve() == 0 and snes.solve() >= 1
        diff = _max_diff(fast, snes, msh.comm)
        print(f"step {n}: fast vs SNES max |dz| = {diff:.2e}")
        assert diff < 1e-10
        for s in (fast, snes):
            s.zeta_old.x.array[:] = s.zeta.x.array
    assert _count(fast, lambda z: (z <= ZETA_STAR) | (z >= 1.0), msh.comm) == 0
    assert fast.counts() == {"damage_vi_fast_hits": 3, "damage_vi_fast_unchanged": 0,
                             "damage_vi_fast_fallbacks": 0, "damage_vi_fast_skipped": 0,
                             "damage_vi_fast_setups": 1}
    assert snes.counts() == {}


@pytest.mark.parametrize("solver", ["auto", "cholesky"])
def test_nodes_held_at_zeta_star(unit_square, solver):
    msh = unit_square(20)
    x = ufl.SpatialCoordinate(msh)
    r2 = (x[0] - 0.5) ** 2 + (x[1] - 0.5) ** 2
    phi = ufl.conditional(ufl.lt(r2, 0.3 ** 2), -50.0, 0.5)  # drives the disc below zeta_star

    def zeta0(X):
        return np.where((X[0] - 0.5) ** 2 + (X[1] - 0.5) ** 2 < 0.35 ** 2, ZETA_STAR, 0.5)

    fast, snes = _pair(msh, zeta0, phi, "lo" + solver, solver)
    assert fast.solve() == 0 and snes.solve() >= 1
    held = _count(fast, lambda z: z == ZETA_STAR, msh.comm)
    diff = _max_diff(fast, snes, msh.comm)
    print(f"{held} nodes at zeta_star; fast vs SNES max |dz| = {diff:.2e}; {fast.counts()}")
    assert held > 20 and diff < 1e-10
    assert fast.counts()["damage_vi_fast_hits"] == 1 and fast.counts()["damage_vi_fast_setups"] == 1


def test_set_changing_within_the_step_goes_to_the_snes(unit_square):
    """A source that pushes zeta through both bounds in one step: the first SNES iteration
    does not converge, so the fast path must hand over; the result is the SNES's, bit for bit."""
    msh = unit_square(16)
    x = ufl.SpatialCoordinate(msh)
    phi = 60.0 * ufl.sin(2 * np.pi * x[0]) * ufl.cos(np.pi * x[1])
    fast, snes = _pair(msh, lambda X: 0.5 + 0.45 * np.sin(3 * X[0]) * np.cos(2 * X[1]), phi, "ch")
    its_fast, its_snes = fast.solve(), snes.solve()
    assert its_fast == its_snes >= 2
    assert fast.counts()["damage_vi_fast_fallbacks"] == 1 and fast.counts()["damage_vi_fast_hits"] == 0
    assert np.array_equal(_owned(fast), _owned(snes))
    assert _count(fast, lambda z: z == ZETA_STAR, msh.comm) > 5
    assert _count(fast, lambda z: z == 1.0, msh.comm) > 5


def test_bad_option_is_refused(unit_square):
    from damage_dolfinx.core.parameters import InputError
    PETSc.Options()["badopt_vi_fast_solver"] = "lu"
    msh = unit_square(4)
    Z = compat.scalar_p1(msh)
    with pytest.raises(InputError, match="vi_fast_solver"):
        DamageStep(fem.Function(Z), fem.Function(Z), ufl.as_ufl(0.0), fem.Constant(msh, K),
                   fem.Constant(msh, KAPPA), SolveContext("bad"), obstacle=True,
                   prefix="badopt_")
    PETSc.Options().delValue("badopt_vi_fast_solver")


RUN = ["run", "3.1-ex2", "--n", "6", "--T", "0.3", "--no-figures", "--quiet"]


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="runs the CLI itself")
def test_run_to_zeta_star_serial_two_ranks_and_snes(tmp_path):
    """3.1-ex2 until a fifth of the nodes sit at zeta_star (the active set grows, some steps go
    to the SNES): the fast path with its default solvers (Cholesky of B for an empty active set:
    PETSc's serially, MUMPS's on 2 ranks), with CG only (the SNES's Newton step: equal bit for bit) and
    with Cholesky only, against the SNES alone."""
    runs = {"snes": (["-damage_vi_fast", "0"], 1), "s": ([], 1), "p": ([], 2),
            "cg": (["-damage_vi_fast_solver", "cg"], 1),
            "cholesky": (["-damage_vi_fast_solver", "cholesky"], 1)}
    for name, (opts, ranks) in runs.items():
        run_cli(RUN + opts + ["--out", tmp_path / name], np_=ranks)
    out = {name: load_run(tmp_path / name) for name in runs}
    counts, (reference, fields) = out["s"][0]["iterations"], out["snes"]
    print(counts, "SNES alone:", reference["iterations"])
    assert counts["damage_vi_fast_hits"] > 50 and counts["damage_vi_fast_fallbacks"] > 0
    assert counts["damage_vi_fast_hits"] + counts["damage_vi_fast_fallbacks"] + \
        counts["damage_vi_fast_skipped"] == reference["steps_done"]
    assert counts["damage_snes"] < reference["iterations"]["damage_snes"]
    assert "damage_vi_fast_hits" not in reference["iterations"]
    for name in ("p", "cg", "cholesky"):
        assert out[name][0]["iterations"]["damage_vi_fast_hits"] == counts["damage_vi_fast_hits"]
    held = int(np.sum(fields["zeta"] == ZETA_STAR))
    assert 10 < held < 0.5 * fields["zeta"].size, held
    for field in ("u", "zeta", "von_mises"):
        diffs = {name: rel_diff(out[name][1][field], fields[field])
                 for name in ("s", "p", "cg", "cholesky")}
        print(f"{field} against the SNES alone: {diffs}")
        assert max(diffs.values()) < 1e-10 and diffs["cg"] == 0.0, field

