"""Section 2.1: quasistatic elastic body with damage (PDE damage law), scheme (2.20)-(2.21).

    u_0:  (eta_*(zeta_0) B eps(u_0), eps(w)) = L_0(w)
    n>=1: (zeta_n - zeta_{n-1}, xi) + k kappa (grad zeta_n, grad xi)
              = k (phi_B(eps(u_{n-1}), zeta_{n-1}), xi)                      (2.20), linear, SPD
          (eta_*(zeta_n) B eps(u_n), eps(w)) = L_n(w)                        (2.21), new damage

The damage matrix is constant (assembled and factorised once). The elasticity matrix changes
with zeta_n and is re-assembled in place each step; it is solved by CG preconditioned with the
exact factorisation of an earlier step's matrix (PETSc's Cholesky serially, MUMPS LU in
parallel: solvers.lagged_direct), rebuilt only when CG needs more than
MECH_REFACTOR_ITS iterations (``-mech_ksp_type preonly`` gives a fresh factorisation per step).
The damage field that factorisation was built from is part of the checkpoint, so that a restart
rebuilds the same preconditioner and resumes exactly. The run stops when min zeta_n <= zeta_star
(flag ``stop_at_zeta_star``, docs/models.md, section 2.1).
Solver prefixes: ``damage_`` (damage PDE) and ``mech_`` (elasticity).
"""
from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem

from damage_dolfinx import compat
from damage_dolfinx.numerics import scalable
from damage_dolfinx.numerics.damage import DamageStep
from damage_dolfinx.forms.elastic_damage import equilibrium_forms, stress
from damage_dolfinx.numerics.boundary import bilateral_plane_faces, clamped
from damage_dolfinx.forms.constitutive import eps, von_mises
from damage_dolfinx.core.tags import GAMMA_C, GAMMA_D, GAMMA_N
from damage_dolfinx.numerics.solvers import LinearSolver, lagged_direct

#: CG iterations above which the lagged elasticity factorisation is rebuilt
MECH_REFACTOR_ITS = 8
from damage_dolfinx.models.base import Model, SubStep
from damage_dolfinx.core.parameters import ModelParameters


class ElasticDamage(Model):
    """Problem VP^{hk} of Section 2.1."""

    id = "2.1"
    title = "quasistatic elastic body with damage"
    contact_roles = ("bilateral",)
    #: u, zeta and the lagged preconditioner's damage (see checkpoint_state)
    checkpoint_fields = ("u", "zeta", "zeta_pc")
    old_state = (("zeta", "zeta_old"),)  # u_{n-1} stays in u until (2.21) replaces it

    @classmethod
    def defaults(cls) -> ModelParameters:
        return ModelParameters(E=1e4, nu=0.33, kappa=1.0, zeta_star=0.01, q_star=1000.0,
                               variant="B", lam_D=0.1, lam_w=0.0, lam_u_plus=1000.0,
                               lam_u_minus=100.0, stop_at_zeta_star=True)

    def __init__(self, data, mech_prefix="mech_", damage_prefix="damage_"):
        super().__init__(data)
        p, msh = self.params, self.mesh
        V, Z = compat.vector_p1(msh), compat.scalar_p1(msh)
        self.u = fem.Function(V, name="u")
        self.zeta = fem.Function(Z, name="zeta")
        self.zeta_old = fem.Function(Z, name="zeta_old")
        self.k = fem.Constant(msh, float(data.time.k))
        self.kappa = fem.Constant(msh, float(p.kappa))

        # (2.20): source from step n-1 (u still holds u_{n-1} when the damage step runs)
        phi_old = self.damage_source(eps(self.u), self.zeta_old)
        self.damage = DamageStep(self.zeta, self.zeta_old, phi_old, self.k, self.kappa,
                                 self.context, obstacle=False, zeta_star=p.zeta_star,
                                 prefix=damage_prefix, linear_defaults=scalable.damage_config(Z),
                                 irreversible=data.irreversible)

        # (2.21): elasticity with the new damage zeta_n
        tags = data.geometry.facet_tags
        dsN = ufl.Measure("ds", domain=msh, subdomain_data=tags)(GAMMA_N)
        w = ufl.TestFunction(V)
        f_B, f_N = self.loads()
        a, L = equilibrium_forms(ufl.TrialFunction(V), w, self.zeta, p.E, p.nu, p.zeta_star,
                                 f_B, f_N, dsN)
        # Gamma_C, empty in every thesis example of 2.1, is read as bilateral contact u.nu = 0
        # on coordinate-plane faces (rollers of the 3-D uniaxial-strain check)
        bcs = [clamped(V, tags, GAMMA_D)] + bilateral_plane_faces(V, tags, GAMMA_C)
        # 2-D: lagged direct; 3-D: CG + AMG with the rigid-body near-nullspace (scalable.py)
        defaults, refactor_its = scalable.mech_config(V, lagged_direct(msh.comm),
                                                      MECH_REFACTOR_ITS)
        self.mech = LinearSolver(a, L, bcs, mech_prefix, self.context, defaults=defaults,
                                 refactor_after_its=refactor_its)
        scalable.prepare_mech(self.mech, V)
        # the damage the lagged factorisation was built from, and 1.0 when the next solve
        # factorises afresh anyway (checkpointed: a restart rebuilds the same preconditioner)
        self.zeta_pc = fem.Function(Z, name="zeta_pc")
        self._pc_due = np.ones(1)

        # output: von Mises of the model stress, DG0 (docs/models.md, "Output conventions")
        Q = compat.scalar_dg0(msh)
        self.von_mises = fem.Function(Q, name="von_mises")
        self._vm_expr = compat.expression(
            von_mises(stress(self.u, self.zeta, p.E, p.nu, p.zeta_star)), Q)
        self.output_fields = [self.u, self.zeta, self.von_mises]
        self.timings = {"damage": 0.0, "mech": 0.0}
        self._prefixes = damage_prefix, mech_prefix

    def scheme(self) -> tuple:
        damage_prefix, mech_prefix = self._prefixes
        return (SubStep("damage", "linear", damage_prefix, self.damage.solve,   # (2.20)
                        its=("damage_its",)),
                SubStep("mech", "linear", mech_prefix, self._solve_mech,        # (2.21)
                        its=("mech_its",)))

    def start(self) -> dict:
        its = self._timed("mech", self._solve_mech)  # u_0 with zeta_0
        self.update_output()
        return {"mech_its": its}

    def _solve_mech(self) -> int:
        """(2.21) by the lagged factorisation, recording the damage it was built from."""
        factorizations = self.mech.factorizations
        its = self.mech.solve(self.u)
        if self.mech.lagged and self.mech.factorizations != factorizations:
            self.zeta_pc.x.array[:] = self.zeta.x.array
        self._pc_due[0] = float(not self.mech.lagged or its > self.mech.refactor_after_its)
        return its

    def checkpoint_state(self) -> dict:
        """u, zeta and the lagged preconditioner's damage zeta_pc (with the flag _pc_due):
        without them a restart factorises at its first step and the resumed run differs at the
        CG tolerance (4e-13 serially, 1.1e-12 on 2 ranks after 10 restarts)."""
        return {**super().checkpoint_state(), "mech_pc_due": self._pc_due}

    def restore(self, n: int):
        super().restore(n)
        if self.mech.lagged and not self._pc_due[0]:  # rebuild the factorisation of A(zeta_pc)
            zeta_n = self.zeta.x.array.copy()
            self.zeta.x.array[:] = self.zeta_pc.x.array
            self.mech.factorise_now()
            self.zeta.x.array[:] = zeta_n

    def update_output(self):
        compat.interpolate(self.von_mises, self._vm_expr)

    def iteration_totals(self) -> dict:
        return {"damage_ksp": self.damage.iterations, "mech_ksp": self.mech.iterations,
                "mech_factorizations": self.mech.factorizations, "snes": 0}
