"""Direct against CG + AMG on one 2-D system of a run (the measurement behind
``AMG_MIN_DOFS[2]`` in damage_dolfinx/numerics/scalable.py, docs/solvers.md): the example is
built at size n, stepped twice, and the chosen system (``mech``: elasticity / velocity;
``damage``: the damage matrix) is set up and solved 3 times (the fastest kept) by each
configuration; the last column is the relative difference to the first configuration's solution.

    [mpirun -n 2] .venv/bin/python benchmarks/performance/solver_crossover_2d.py 2.1-ex1 720 mech chol_nd,gamg_def
"""
import argparse
import time

from mpi4py import MPI
from petsc4py import PETSc
from damage_dolfinx.catalogue import examples
from damage_dolfinx.numerics import scalable
ap = argparse.ArgumentParser(description="direct against CG + AMG on one 2-D system of a run")
ap.add_argument("example")
ap.add_argument("n", type=int)
ap.add_argument("system", nargs="?", default="mech", choices=("mech", "damage"))
ap.add_argument("configs", nargs="?", default=None, help="comma-separated configuration names")
args = ap.parse_args()
ex_id, n, which = args.example, args.n, args.system
comm = MPI.COMM_WORLD
ex = examples.get(ex_id)
k = 0.01 if ex_id.startswith("2.1") else 0.005
kw = {}
st = ex.build(comm, n=n, k=k, T=k * 3)
st.initialize(); st.advance(); st.advance()
if which == "mech":
    A, b = st.mech.A, st.mech.b
    V = st.mech.a.function_spaces[0]
else:
    lin = st.damage.linear if hasattr(st.damage, "linear") else None
    A, b = (lin.A, lin.b) if lin else (st.damage.A, st.damage.b)
print(ex_id, which, "size", A.getSize(), "bs", A.getBlockSize(), flush=True)
base = dict(scalable._KRYLOV)
configs = {
 "chol_nat": {"ksp_type": "preonly", "pc_type": "cholesky", "pc_factor_mat_solver_type": "petsc"},
 "chol_nd": {"ksp_type": "preonly", "pc_type": "cholesky", "pc_factor_mat_solver_type": "petsc", "pc_factor_mat_ordering_type": "nd"},
 "mumps": {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"},
 "gamg_def": scalable.MECH_AMG,
 "gamg_t0": {**scalable.MECH_AMG, "pc_gamg_threshold": 0.0},
 "gamg_t05": {**scalable.MECH_AMG, "pc_gamg_threshold": 0.05},
 "gamg_cheb3": {**scalable.MECH_AMG, "mg_levels_ksp_max_it": 3},
 "gamg_sor": {**scalable.MECH_AMG, "mg_levels_ksp_type": "richardson", "mg_levels_pc_type": "sor"},
 "hypre": {**base, "pc_type": "hypre", "pc_hypre_type": "boomeramg"},
 "hypre_nodal": {**base, "pc_type": "hypre", "pc_hypre_type": "boomeramg", "pc_hypre_boomeramg_nodal_coarsen": 6, "pc_hypre_boomeramg_vec_interp_variant": 3, "pc_hypre_boomeramg_strong_threshold": 0.5},
 "hypre_hmis": {**base, "pc_type": "hypre", "pc_hypre_type": "boomeramg", "pc_hypre_boomeramg_coarsen_type": "HMIS", "pc_hypre_boomeramg_interp_type": "ext+i", "pc_hypre_boomeramg_P_max": 4},
 "hypre_hmis_agg": {**base, "pc_type": "hypre", "pc_hypre_type": "boomeramg", "pc_hypre_boomeramg_coarsen_type": "HMIS", "pc_hypre_boomeramg_interp_type": "ext+i", "pc_hypre_boomeramg_P_max": 4, "pc_hypre_boomeramg_agg_nl": 1},
 "hypre_pmis_s5": {**base, "pc_type": "hypre", "pc_hypre_type": "boomeramg", "pc_hypre_boomeramg_coarsen_type": "PMIS", "pc_hypre_boomeramg_interp_type": "ext+i", "pc_hypre_boomeramg_P_max": 4, "pc_hypre_boomeramg_strong_threshold": 0.5},
 "gamg_sq": {**scalable.MECH_AMG, "pc_gamg_square_graph": 10},
 "gamg_cheb1": {**scalable.MECH_AMG, "mg_levels_ksp_max_it": 1},
 "gamg_nosm": {**scalable.MECH_AMG, "pc_gamg_agg_nsmooths": 0},
 "gamg_t01_sq": {**scalable.MECH_AMG, "pc_gamg_threshold": 0.01, "pc_gamg_square_graph": 10},
 "gamg_rt8": {**scalable.MECH_AMG, "ksp_rtol": 1e-8},
 "cg_jacobi": {**base, "pc_type": "jacobi", "ksp_max_it": 20000},
}
only = args.configs.split(",") if args.configs else list(configs)
if which == "mech":
    A.setNearNullSpace(scalable.rigid_body_modes(V))
x0 = b.duplicate()
for name in only:
    cfg = configs[name]
    if A.getSize()[0] > 400000 and name == "chol_nat": continue
    opts = PETSc.Options()
    pre = f"t{name}_"
    for kk, v in cfg.items(): opts[pre + kk] = v
    ksp = PETSc.KSP().create(comm); ksp.setOptionsPrefix(pre); ksp.setOperators(A); ksp.setFromOptions()
    comm.Barrier(); t0 = time.perf_counter(); ksp.setUp(); comm.Barrier(); tsetup = time.perf_counter() - t0
    ts = []
    for r in range(3):
        x = b.duplicate(); x.set(0.0)
        comm.Barrier(); t0 = time.perf_counter(); ksp.solve(b, x); comm.Barrier(); ts.append(time.perf_counter() - t0)
    if name == only[0] or name == "chol_nat": ref = x.copy()
    diff = (x - ref).norm() / ref.norm()
    if comm.rank == 0:
        print(f"{name:12s} setup {tsetup:8.3f}  solve {min(ts):8.4f}  its {ksp.getIterationNumber():4d} reason {ksp.getConvergedReason()} diff {diff:.1e}", flush=True)
    ksp.destroy()
