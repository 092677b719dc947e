"""Contact quantities as outputs: what the foundation does to the body on Gamma_C, per step.

One object for every model with a contact role: the run attaches it to its model
(``ContactOutput.for_model``), which adds history.csv columns and XDMF fields to the model.

Nodal contact forces. With the vertex (trapezoidal) rule on Gamma_C, node i of Gamma_C carries
the weight m_i = int_{Gamma_C} phi_i ds, the lumped unit normal nu_i (int nu phi_i ds,
normalised) and the force F_i the foundation exerts on the body:

* normal compliance (a ``pressure`` p = p_nu(u.nu - gap) >= 0 given):  F_i = -int p nu phi_i ds
  (with the quadrature of the models' contact terms, PRESSURE_DEGREE);
* bilateral contact and friction (a ``residual`` R(w) = a(v, w) - l(w) of the step without its
  contact constraint): F_i = R(phi_i) = int_{Gamma_C} sigma nu . phi_i ds, the reaction of the
  constraint (normal) and the friction force (tangential) together; nodes of the clamped part
  Gamma_D are left out of the forces (their rows hold the clamping reaction).

The pressure is p_i = -F_i.nu_i / m_i, the friction traction F_tau,i / m_i with
F_tau = F - (F.nu) nu. history.csv gets, per step:

    contact_normal_force     sum_i -F_i.nu_i (the normal resultant, > 0 in compression)
    contact_force_x, _y(, _z) sum_i F_i (the resultant the foundation exerts on the body)
    contact_length / _area   sum of m_i where p_i > 0 (normal compliance), all of Gamma_C
                             (bilateral: in contact by construction)
    contact_penetration      max_i (u_i.nu_i - gap)_+ (bilateral: max_i |u_i.nu_i|, zero up to
                             round-off)
    friction_force           2-D: sum_i F_i.tau_i, tau = (-nu_2, nu_1); 3-D: |sum_i F_tau,i|
    slip_length / slip_area  sum of m_i where |v_tau,i| > eps_reg (the regularised law slides)

and the XDMF series the P1 fields ``contact_pressure`` and ``friction_traction`` (zero off
Gamma_C).
"""
from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from damage_dolfinx import compat
from damage_dolfinx.core.tags import GAMMA_C, GAMMA_D
from damage_dolfinx.numerics import bookkeeping
from damage_dolfinx.forms.contact import (NODAL_QUADRATURE, NODAL_QUADRATURE_3D,  # noqa: F401
                                             normal_compliance_pressure)


#: quadrature degree of the normal compliance force: that of the models' contact terms, so that
#: sum_i F_i is the force the scheme applies (the pressure has kinks inside facets)
PRESSURE_DEGREE = 2


#: cell tag of the strip of cells that touch Gamma_C (:func:`near_contact`)
STRIP = 1


def near_contact(form, V, facet_tags):
    """``form`` (UFL, linear in a test function of V) with its cell integrals restricted to the
    owned cells that have a node on Gamma_C: the same entries at every node of Gamma_C (each
    gathers the cells around it; only the order of the sums changes), an assembly over a strip
    of cells instead of the whole mesh (a fraction of the cost). Facet integrals
    are kept as they are. ``form`` unchanged where a cell integral already has a subdomain."""
    cells = [itg for itg in form.integrals() if itg.integral_type() == "cell"]
    if not cells or any(itg.subdomain_id() not in ("everywhere", "otherwise")
                        or itg.subdomain_data() is not None for itg in cells):
        return form
    msh = V.mesh
    w = ufl.TestFunction(compat.scalar_p1(msh))
    ds = ufl.Measure("ds", domain=msh, subdomain_data=facet_tags)
    on_facets = compat.form(w * ds(GAMMA_C))
    marker = compat.create_vector(on_facets)
    with marker.localForm() as local:
        local.set(0.0)
    compat.assemble_vector(marker, on_facets)
    marker.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    marker.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
    with marker.localForm() as local:
        on_gamma_c = local.array.copy() > 0
    marker.destroy()
    Z = w.ufl_function_space()
    strip = np.flatnonzero(on_gamma_c[compat.cell_dofs(Z)].any(axis=1))
    tags = compat.meshtags(msh, msh.topology.dim, strip, np.full(strip.size, STRIP))
    return ufl.Form([itg.reconstruct(subdomain_id=STRIP, subdomain_data=tags)
                     if itg.integral_type() == "cell" else itg for itg in form.integrals()])


def _assemble(form):
    """Owned entries of an assembled vector (ghost contributions added)."""
    vec = compat.create_vector(form)
    with vec.localForm() as local:
        local.set(0.0)
    compat.assemble_vector(vec, form)
    vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    return vec.getArray().copy()


class ContactOutput:
    """The contact quantities of one stepper (module docstring)."""

    def __init__(self, stepper, pressure=None, gap=0.0, residual=None, slip_rate=None,
                 eps_slip=None):
        msh, self.comm = stepper.mesh, stepper.comm
        self.dim = msh.topology.dim
        self.u, self.V = stepper.u, stepper.u.function_space
        tags = stepper.data.geometry.facet_tags
        rule = NODAL_QUADRATURE if self.dim == 2 else NODAL_QUADRATURE_3D
        ds = ufl.Measure("ds", domain=msh, subdomain_data=tags, metadata=rule)
        w, n = ufl.TestFunction(self.V), ufl.FacetNormal(msh)
        bs, owned = self.dim, self.V.dofmap.index_map.size_local
        self.m = _assemble(compat.form(w[0] * ds(GAMMA_C))).reshape(-1, bs)[:, 0]
        clamped = _assemble(compat.form(w[0] * ds(GAMMA_D))).reshape(-1, bs)[:, 0]
        self.gap, self.compliance = float(gap), pressure is not None
        self.nodes = np.flatnonzero((self.m > 0) & ((clamped == 0) | self.compliance))
        self.length = self.comm.allreduce(float(self.m[:owned].sum()), op=MPI.SUM)
        normal = _assemble(compat.form(ufl.dot(n, w) * ds(GAMMA_C))).reshape(-1, bs)
        normal = normal[self.nodes]
        self.nu = normal / np.maximum(np.linalg.norm(normal, axis=1), 1e-300)[:, None]
        self._m_nodes = self.m[self.nodes]
        self._tau = np.column_stack([-self.nu[:, 1], self.nu[:, 0]]) if self.dim == 2 else None
        dsq = ufl.Measure("ds", domain=msh, subdomain_data=tags,
                          metadata={"quadrature_degree": PRESSURE_DEGREE})
        force = -pressure * ufl.dot(n, w) * dsq(GAMMA_C) if self.compliance else residual
        if not self.compliance and not isinstance(force, tuple):
            force = near_contact(force, self.V, tags)  # only its rows on Gamma_C are read
        self._force = force if isinstance(force, tuple) else compat.form(force)
        self.slip_rate, self.eps_slip = slip_rate, eps_slip
        self.columns = self.names(self.dim, slip_rate is not None)
        self._size = "length" if self.dim == 2 else "area"
        Z = compat.scalar_p1(msh)
        self.pressure = fem.Function(Z, name="contact_pressure")
        self._z_nodes = self._matching_nodes(Z, owned)
        self.fields = [self.pressure]
        if slip_rate is not None:
            self.traction = fem.Function(self.V, name="friction_traction")
            self.fields.append(self.traction)

    @staticmethod
    def names(dim: int, friction: bool) -> list:
        """The history columns of the contact outputs on a mesh of dimension ``dim``
        (``friction``: with a slip rate, the friction force and the sliding part)."""
        size = "length" if dim == 2 else "area"
        return (["contact_normal_force"] + [f"contact_force_{c}" for c in "xyz"[:dim]]
                + [f"contact_{size}", "contact_penetration"]
                + (["friction_force", f"slip_{size}"] if friction else []))

    def _matching_nodes(self, Z, owned):
        """Owned dofs of the scalar P1 space Z at the contact nodes (matched by coordinates)."""
        xz = np.round(Z.tabulate_dof_coordinates()[:Z.dofmap.index_map.size_local], 12)
        xv = np.round(self.V.tabulate_dof_coordinates()[:owned][self.nodes], 12)
        lookup = {tuple(x): i for i, x in enumerate(xz)}
        found = np.array([lookup.get(tuple(x), -1) for x in xv], dtype=np.int64)
        self._z_found = found >= 0  # a vertex owned by another rank in Z: its owner writes it
        return found[self._z_found]

    @classmethod
    def attach(cls, stepper, **kwargs):
        """Add the contact columns and fields to ``stepper`` (its ``scalars()`` and
        ``update_output()`` report them); nothing when its Gamma_C is empty. Call it at the end
        of the stepper's constructor."""
        tags = stepper.data.geometry.facet_tags
        if not stepper.comm.allreduce(int(np.sum(tags.values == GAMMA_C)), op=MPI.SUM):
            return None
        out = cls(stepper, **kwargs)
        stepper.extra_history_columns = list(stepper.extra_history_columns) + out.columns
        stepper.output_fields = list(stepper.output_fields) + out.fields
        scalars, update = stepper.scalars, stepper.update_output
        stepper.scalars = lambda: {**scalars(), **out.scalars()}
        stepper.update_output = lambda: (update(), out.update())
        stepper.contact_output = out
        return out

    @classmethod
    def for_model(cls, stepper):
        """Attach the contact outputs that fit ``stepper`` (a model): normal compliance when it
        has a contact pressure (``contact_pressure()``), the reaction and friction of its
        friction problem (``friction_problem``: a, l, v), the reaction of its linear mechanical
        solve (``mech``: a, L of a bilateral Gamma_C); nothing otherwise."""
        pressure = stepper.contact_pressure() if hasattr(stepper, "contact_pressure") else None
        if pressure is not None:
            gap = float(stepper.params.extra.get("gap", 0.0))
            return cls.attach(stepper, pressure=pressure, gap=gap)
        problem = getattr(stepper, "friction_problem", None)
        if problem is not None:
            out = cls.attach(stepper, residual=ufl.action(problem.a, problem.v) - problem.l,
                             slip_rate=problem.v,
                             eps_slip=float(stepper.params.extra.get("eps_reg", 1e-9)))
            if out is not None:
                out.tap_friction_rhs(stepper, problem)
            return out
        mech = getattr(stepper, "mech", None)
        if "bilateral" in getattr(stepper, "contact_roles", ()) and hasattr(mech, "a") \
                and hasattr(mech, "L"):
            return cls.attach(stepper, residual=(mech.a, mech.L))
        return None

    def tap_friction_rhs(self, stepper, problem):
        """Serially, where the friction solver assembles l itself every step (its algebraic
        residual's ``rhs_taps``): the reaction R = A v - l at the contact nodes from the rows of
        A there (the matrix of ``a`` without boundary conditions, assembled once) and the
        entries of l there, copied as the solver assembles l. The same numbers as the residual
        assembled over the strip of cells (sums in another order), without an assembly per row.
        Used for the step whose l was
        tapped (``stepper.n``); any other step, and on several ranks, assembles."""
        residual = getattr(getattr(stepper, "friction", None), "residual", None)
        taps = getattr(residual, "rhs_taps", None)
        if taps is None or self.comm.size > 1:
            return
        import scipy.sparse
        a = compat.form(problem.a)
        A = compat.create_matrix(a)
        compat.assemble_matrix(A, a, [])
        A.assemble()
        indptr, indices, values = A.getValuesCSR()
        rows = (self.dim * self.nodes[:, None] + np.arange(self.dim)).ravel()
        self._rows = scipy.sparse.csr_matrix((values, indices, indptr), shape=A.getSize())[rows]
        A.destroy()
        self._tapped = {"v": problem.v.x.array, "l": np.zeros(rows.size), "at": None,
                        "stepper": stepper}

        def tap(b):
            self._tapped["l"][:] = b.getArray(readonly=True)[rows]
            self._tapped["at"] = stepper.n
        taps.append(tap)

    def _nodal(self, tangential=True):
        """(F (nodes, dim), p (nodes,), F_tau (nodes, dim), or None without ``tangential``) on
        the owned contact nodes."""
        tapped = getattr(self, "_tapped", None)
        if tapped is not None and tapped["at"] == tapped["stepper"].n:
            F = (self._rows @ tapped["v"] - tapped["l"]).reshape(-1, self.dim)
        else:
            F = self._forces().reshape(-1, self.dim)[self.nodes]
        Fn = np.einsum("ij,ij->i", F, self.nu)
        return F, -Fn / self._m_nodes, F - Fn[:, None] * self.nu if tangential else None

    def _forces(self):
        """Owned entries of the nodal force vector: an assembled linear form (into a vector
        made once), or A u - b of a compiled (a, L) pair (a linear solve's forms, without its
        boundary conditions)."""
        if not isinstance(self._force, tuple):
            if not hasattr(self, "_vector"):
                self._vector = compat.create_vector(self._force)
            vec = self._vector
            with vec.localForm() as local:
                local.set(0.0)
            compat.assemble_vector(vec, self._force)
            vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
            return vec.getArray(readonly=True)
        a, L = self._force
        if not hasattr(self, "_matrix"):
            self._matrix = compat.create_matrix(a)
        A = self._matrix
        A.zeroEntries()
        compat.assemble_matrix(A, a, [])
        A.assemble()
        r = A.createVecLeft()
        A.mult(compat.petsc_vec(self.u), r)
        b = compat.create_vector(L)
        with b.localForm() as local:
            local.set(0.0)
        compat.assemble_vector(b, L)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        r.axpy(-1.0, b)
        out = r.getArray().copy()
        r.destroy()
        b.destroy()
        return out

    def _owned_nodes(self):
        """(u, v or None) at the owned contact nodes, (nodes, dim), from views of the owned
        values taken once."""
        if not hasattr(self, "_views"):
            n = self.V.dofmap.index_map.size_local * self.dim
            self._views = [f.x.array[:n].reshape(-1, self.dim) if f is not None else None
                           for f in (self.u, self.slip_rate)]
        return [None if a is None else a[self.nodes] for a in self._views]

    def scalars(self) -> dict:
        F, p, F_tau = self._nodal(tangential=self.slip_rate is not None)
        m, d, nu = self._m_nodes, self.dim, self.nu
        u, v = self._owned_nodes()
        un = np.einsum("ij,ij->i", u, nu)
        if self.compliance:
            in_contact, penetration = p > 0, np.maximum(un - self.gap, 0.0)
        else:
            in_contact, penetration = None, np.abs(un)
        sums = [np.dot(p, m), *F.sum(axis=0), np.sum(m[in_contact]) if self.compliance else 0.0]
        if v is not None:
            v_tau = v - np.einsum("ij,ij->i", v, nu)[:, None] * nu
            sliding = np.sqrt(np.einsum("ij,ij->i", v_tau, v_tau)) > self.eps_slip
            if d == 2:
                sums += [np.sum(F_tau * self._tau), np.sum(m[sliding])]
            else:
                sums += [*F_tau.sum(axis=0), np.sum(m[sliding])]
        sums, (peak,) = bookkeeping.sums_and_maxima(
            self.comm, sums, [float(penetration.max()) if penetration.size else 0.0])
        size = sums[d + 1] if self.compliance else self.length  # bilateral: all of Gamma_C
        out = {"contact_normal_force": sums[0], f"contact_{self._size}": size,
               "contact_penetration": peak,
               **{f"contact_force_{c}": sums[1 + i] for i, c in enumerate("xyz"[:d])}}
        if v is not None:
            friction = sums[d + 2] if d == 2 else float(np.linalg.norm(sums[d + 2:2 * d + 2]))
            out.update({"friction_force": float(friction), f"slip_{self._size}": sums[-1]})
        return {key: float(value) for key, value in out.items()}

    def update(self):
        """The contact_pressure (and friction_traction) fields of the current state."""
        F, p, F_tau = self._nodal()
        self.pressure.x.array[:] = 0.0
        self.pressure.x.array[self._z_nodes] = p[self._z_found]
        self.pressure.x.scatter_forward()
        if self.slip_rate is not None:
            values = self.traction.x.array.reshape(-1, self.dim)
            values[:] = 0.0
            values[self.nodes] = F_tau / self.m[self.nodes][:, None]
            self.traction.x.scatter_forward()
