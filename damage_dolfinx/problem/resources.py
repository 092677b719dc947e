"""Memory estimate of a run before any work: a mesh that cannot fit is refused with a message.

The estimate scales the vertex count of the example's default mesh (built once on one rank, only
when the requested mesh is more than 4x finer) quadratically with n / n_default or h_default / h,
and charges per vertex a little more than the heaviest 2-D runs took (peak RSS, serial, thesis
factorisations included; the figures: benchmarks/README.md, "Why the defaults"): so
BYTES_PER_VERTEX = 10 kB (direct factorisations fill in slightly faster than linearly) plus
BASE_BYTES = 200 MB per rank (Python, PETSc, the JIT). The total is compared with the available
memory (MemAvailable of /proc/meminfo) summed over the distinct hosts of the MPI job.
"""
from __future__ import annotations

import socket

BYTES_PER_VERTEX = 10e3
BASE_BYTES = 200e6
#: the check builds the default mesh only for requests finer than this many times its vertices
CHECK_ABOVE = 4.0


def available_bytes():
    """MemAvailable of this host in bytes, or None where /proc/meminfo does not tell."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024.0
    except OSError:
        pass
    return None


def _scale(ex, n, h) -> float:
    """(requested vertices) / (default vertices), from the mesh-size ratio to the power of the
    dimension (2, or 3 for 3-D examples: there BYTES_PER_VERTEX also holds, for 2.1-ex1-3d with
    its AMG solvers)."""
    dim = getattr(ex, "dim", 2)
    if n is not None and ex.n:
        return (n / ex.n) ** dim
    if h is not None and ex.h:
        return (ex.h / h) ** dim
    return 1.0


def _default_vertices(ex) -> int:
    from mpi4py import MPI
    geometry = ex.make_geometry(MPI.COMM_SELF, ex.n, ex.h)
    imap = geometry.mesh.topology.index_map(0)
    return int(imap.size_global)


def check_memory(ex, n, h, comm):
    """Raise InputError when the estimated memory of a run exceeds what the job's hosts have."""
    from damage_dolfinx.core.parameters import InputError
    scale = _scale(ex, n, h)
    if scale <= CHECK_ABOVE:
        return
    vertices = None
    if comm.rank == 0:
        vertices = _default_vertices(ex) * scale
    vertices = comm.bcast(vertices, root=0)
    need = vertices * BYTES_PER_VERTEX + comm.size * BASE_BYTES
    hosts = comm.allgather((socket.gethostname(), available_bytes()))
    per_host = dict(hosts)
    if any(v is None for v in per_host.values()):
        return
    have = sum(per_host.values())
    if need > have:
        size = f"n = {n}" if n is not None else f"h = {h:g}"
        raise InputError(
            f"{ex.id} with {size} needs about {need / 2**30:.3g} GiB ({vertices:.3g} vertices at "
            f"{BYTES_PER_VERTEX / 1e3:.0f} kB each), but the job's hosts have "
            f"{have / 2**30:.3g} GiB available: choose a coarser mesh")
