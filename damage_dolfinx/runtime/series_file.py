"""The run's fields as one XDMF 3 time series that any reader opens at once.

Layout (``fields.xdmf`` + one ``.h5`` per segment of the run):

* one temporal collection; each output time is ONE grid holding every field as an attribute, so
  ParaView shows one block with all fields (ζ on the deformed shape is one Warp By Vector away)
  and meshio's ``TimeSeriesReader`` reads every field;
* the mesh is written once per segment (``/Mesh/geometry``, ``/Mesh/topology``), its nodes in
  the order of the mesh's input data (DOLFINx's ``input_global_indices``: the generator's or the
  mesh file's node order) and its cells sorted by their nodes. Neither depends on the number of
  ranks, so the segments of a run restarted on another number of ranks hold the same mesh, node
  for node, and a reader that takes one mesh for the whole series puts every value on its node;
* field values are exactly those DOLFINx's own XDMF writer writes (P1: the value at each node,
  DG0: the value of each cell; 2-D vectors padded to 3 components, 2 x 2 tensors to 3 x 3),
  only their order differs.

Writing is collective: each rank sends its owned nodes' (cells') values to rank 0 (one Gatherv
per field), which places them and appends one dataset per field with h5py, then replaces the
XML atomically (write to ``.tmp``, rename), so the XML on disk always describes complete data.
Rank 0 opens the HDF5 file without file locking: a reader that holds the file open (ParaView,
``read_run``, h5py) can never make the run fail.
"""
from __future__ import annotations

import copy
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from damage_dolfinx import compat

#: the Domain name that marks this layout (tensors always 3 x 3, one mesh for the series)
LAYOUT = "damage-dolfinx fields: one grid per time, nodes in input order"

#: HDF5 files (h5py, DOLFINx) whose write or close failed: HDF5 crashes (SIGSEGV) when such a
#: file is destroyed or when HDF5 shuts down, so they are kept alive and the command line ends
#: the process with os._exit when this list is not empty (io.py hands the same list on)
FAILED_HDF5_FILES = []

#: DOLFINx's vertex order -> XDMF's, per cell type (simplices are the same)
_XDMF_ORDER = {"quadrilateral": [0, 1, 3, 2], "hexahedron": [0, 1, 3, 2, 4, 5, 7, 6]}
_XDMF_TOPOLOGY = {"interval": "Polyline", "triangle": "Triangle", "tetrahedron": "Tetrahedron",
                  "quadrilateral": "Quadrilateral", "hexahedron": "Hexahedron"}


def h5_open(path, mode):
    """h5py.File without HDF5 file locking where h5py and HDF5 support it (h5py >= 3.5, HDF5
    >= 1.10.7); raises OSError."""
    import h5py
    try:
        return h5py.File(path, mode, locking=False)
    except TypeError:  # an h5py without the keyword
        return h5py.File(path, mode)
    except OSError as exc:  # already open in this process with locking (meshio keeps it open):
        if "locking flag" not in str(exc):  # HDF5 then wants the same flag, and shares the file
            raise
        return h5py.File(path, mode)
    except ValueError as exc:
        if "locking" not in str(exc).lower():
            raise OSError(str(exc)) from None
        return h5py.File(path, mode)


class MeshOrder:
    """Where each rank's owned geometry nodes and cells go in the rank-independent order
    (collective to build; the permutations live on rank 0)."""

    def __init__(self, msh):
        comm = self.comm = msh.comm
        self.msh = msh
        self.tdim, self.gdim = msh.topology.dim, msh.geometry.dim
        name = compat.cell_type_name(msh)
        if name not in _XDMF_TOPOLOGY:
            raise RuntimeError(f"fields output: cell type {name} is not supported")
        self.cell_name = name
        self.n_nodes = compat.num_owned_nodes(msh)
        self.n_cells = compat.num_owned_cells(msh)
        x_dofmap = compat.geometry_dofmap(msh)
        inputs = compat.geometry_input_indices(msh)
        self.node_counts = np.array(comm.allgather(self.n_nodes), dtype=np.int64)
        self.cell_counts = np.array(comm.allgather(self.n_cells), dtype=np.int64)
        owned_inputs = self._gather(inputs[:self.n_nodes], self.node_counts, np.int64)
        x = self._gather(msh.geometry.x[:self.n_nodes, :self.gdim], self.node_counts)
        cells = self._gather(inputs[x_dofmap[:self.n_cells]], self.cell_counts, np.int64)
        self.node_pos = self.cell_pos = self.geometry = self.topology = None
        if comm.rank == 0:
            owned_inputs = owned_inputs[:, 0]
            unique = np.unique(owned_inputs)
            if unique.size != owned_inputs.size:  # never: every node is owned once
                raise RuntimeError("fields output: mesh nodes with the same input index")
            self.node_pos = np.searchsorted(unique, owned_inputs)
            self.geometry = np.empty_like(x)
            self.geometry[self.node_pos] = x
            rows = np.searchsorted(unique, cells)
            order = np.lexsort(np.sort(rows, axis=1).T[::-1])
            self.cell_pos = np.empty_like(order)
            self.cell_pos[order] = np.arange(order.size)
            topology = rows[order]
            if name in _XDMF_ORDER and topology.shape[1] == len(_XDMF_ORDER[name]):
                topology = topology[:, _XDMF_ORDER[name]]
            self.topology = topology
        self._maps = {}

    def _gather(self, local, rows, dtype=np.float64):
        """All ranks' rows of ``local`` (n, c) concatenated in rank order on rank 0 (``rows``:
        every rank's n, known beforehand: one Gatherv and nothing else)."""
        local = np.ascontiguousarray(local, dtype=dtype)
        if local.ndim == 1:
            local = local[:, None]
        width = local.shape[1]
        counts = rows * width
        out = np.empty((int(counts.sum()) // max(width, 1), width), dtype) \
            if self.comm.rank == 0 else None
        if self.comm.size == 1:
            return local.reshape(-1, width).copy()
        from mpi4py import MPI
        mpitype = MPI.INT64_T if dtype == np.int64 else MPI.DOUBLE
        self.comm.Gatherv(local.reshape(-1), [out, counts, mpitype] if out is not None
                          else None, root=0)
        return out

    def field_map(self, fn):
        """(center, local indices into the block array, components, XDMF attribute type)."""
        V = fn.function_space
        key = id(fn)  # the run's output Functions live as long as the series (kept below)
        if key not in self._maps:
            degree, dg = compat.element_degree(V), compat.is_discontinuous(V)
            dofs = compat.dofmap_array(V)
            if degree == 0:
                center, index = "Cell", dofs[:self.n_cells, 0]
            elif degree == 1 and not dg:
                node_dof = np.empty(self.msh.geometry.x.shape[0], dtype=np.int64)
                x_dofmap = compat.geometry_dofmap(self.msh)
                if x_dofmap.shape[1] != dofs.shape[1]:
                    raise RuntimeError(f"fields output: {fn.name} does not match the mesh's nodes")
                node_dof[x_dofmap.reshape(-1)] = dofs.reshape(-1)
                center, index = "Node", node_dof[:self.n_nodes]
            else:
                raise RuntimeError(f"fields output: {fn.name} is neither P1 nor DG0 (degree "
                                 f"{degree}{', discontinuous' if dg else ''}): interpolate it "
                                 "into one of those to write it")
            self._maps[key] = (fn, center, index)
        _, center, index = self._maps[key]
        shape = tuple(fn.ufl_shape)
        kind = {0: "Scalar", 1: "Vector", 2: "Tensor"}.get(len(shape))
        if kind is None:
            raise RuntimeError(f"fields output: {fn.name} has value shape {shape}")
        return center, index, shape, kind

    def gathered(self, fn):
        """(center, kind, values (N, components) in the rank-independent order) on rank 0,
        (center, kind, None) elsewhere; values padded as DOLFINx's XDMF writer does."""
        center, index, shape, kind = self.field_map(fn)
        bs = int(np.prod(shape)) if shape else 1
        local = fn.x.array.reshape(-1, bs)[index]
        if kind == "Vector" and shape[0] == 2:
            local = np.concatenate([local, np.zeros((local.shape[0], 1))], axis=1)
        elif kind == "Tensor" and shape == (2, 2):
            padded = np.zeros((local.shape[0], 9))
            padded[:, [0, 1, 3, 4]] = local
            local = padded
        data = self._gather(local, self.node_counts if center == "Node" else self.cell_counts)
        if self.comm.rank != 0:
            return center, kind, None
        out = np.empty_like(data)
        out[self.node_pos if center == "Node" else self.cell_pos] = data
        return center, kind, out


def _item(text, dims, number="Float", precision="8"):
    item = ET.Element("DataItem", {"Dimensions": " ".join(map(str, dims)), "Format": "HDF",
                                   "NumberType": number, "Precision": precision})
    item.text = text
    return item


def grid_element(order, h5name, t, attributes):
    """One time's grid: the segment's mesh, the time and ``attributes`` [(name, center, kind,
    dataset path, shape)]."""
    grid = ET.Element("Grid", {"Name": "fields", "GridType": "Uniform"})
    topo = ET.SubElement(grid, "Topology", {
        "TopologyType": _XDMF_TOPOLOGY[order.cell_name],
        "NumberOfElements": str(order.topology.shape[0]),
        "NodesPerElement": str(order.topology.shape[1])})
    topo.append(_item(f"{h5name}:/Mesh/topology", order.topology.shape, "Int"))
    geom = ET.SubElement(grid, "Geometry", {"GeometryType": "XY" if order.gdim == 2 else "XYZ"})
    geom.append(_item(f"{h5name}:/Mesh/geometry", order.geometry.shape))
    ET.SubElement(grid, "Time", {"Value": repr(float(t))})
    for name, center, kind, path, shape in attributes:
        attr = ET.SubElement(grid, "Attribute", {"Name": name, "AttributeType": kind,
                                                 "Center": center})
        attr.append(_item(f"{h5name}:{path}", shape))
    return grid


def grid_xml(grid) -> bytes:
    """One time grid as indented XML text (serialised once: the index is rewritten from these
    pieces after every output time, so a write costs the same at the first and the last time)."""
    grid = copy.deepcopy(grid)
    grid.tail = None
    ET.indent(grid, space="  ", level=3)
    return b"      " + ET.tostring(grid, encoding="utf-8").replace(b"<?xml version='1.0' encoding='utf-8'?>\n", b"").rstrip() + b"\n"


def index_xml(pieces) -> bytes:
    """The whole series from the time grids' XML ``pieces`` (grid_xml) in time order."""
    name = LAYOUT.replace("&", "&amp;").replace('"', "&quot;").replace("<", "&lt;")
    return (b'<?xml version="1.0"?>\n<Xdmf Version="3.0">\n  <Domain Name="'
            + name.encode() + b'">\n    <Grid Name="fields" GridType="Collection" '
            b'CollectionType="Temporal">\n' + b"".join(pieces)
            + b"    </Grid>\n  </Domain>\n</Xdmf>\n")


def _room_for(path, need, replace=False):
    """OSError before HDF5 starts a write that the file-size limit (RLIMIT_FSIZE) would cut:
    HDF5 left with a half-written file crashes the process later."""
    import errno
    import resource
    limit = resource.getrlimit(resource.RLIMIT_FSIZE)[0]
    if limit == resource.RLIM_INFINITY:
        return
    size = 0 if replace or not Path(path).exists() else Path(path).stat().st_size
    if size + need > limit:
        raise OSError(errno.EFBIG, f"File too large (the process's file-size limit is "
                                   f"{limit // 1024} kB; {Path(path).name} would need "
                                   f"~{(size + need) // 1024} kB)")


def _keep_failed(f):
    """A file whose write or close failed is never closed or destroyed again (HDF5 crashes
    doing so); the command line then ends the process without HDF5's shutdown."""
    FAILED_HDF5_FILES.append(f)


class SeriesWriter:
    """The segment ``h5path`` of the run's series and the index ``index`` (fields.xdmf) that
    lists ``earlier`` grids [(t, Grid)] (kept from the runs before a restart) then this
    segment's. Collective: construct and ``write`` on every rank."""

    def __init__(self, msh, h5path, index, earlier=()):
        self.comm, self.h5path, self.index = msh.comm, Path(h5path), Path(index)
        self.order = MeshOrder(msh)
        self.earlier, self.grids, self.count = list(earlier), [], 0
        self._earlier_xml = [grid_xml(g) for _, g in self.earlier] if self.comm.rank == 0 else []
        if self.comm.rank == 0:
            _room_for(self.h5path, self.order.geometry.nbytes + self.order.topology.nbytes
                      + 65536, replace=True)
            f = h5_open(self.h5path, "w")
            try:
                f.create_dataset("/Mesh/geometry", data=self.order.geometry)
                f.create_dataset("/Mesh/topology", data=self.order.topology.astype(np.int64))
                f.close()
            except BaseException:
                _keep_failed(f)
                raise

    def write(self, functions, t, atomic_write):
        """Append ``functions`` at time ``t`` (a time already written by this segment is
        replaced); ``atomic_write(path, bytes)`` writes the index (rank 0)."""
        gathered = [(fn.name, *self.order.gathered(fn)) for fn in functions]
        if self.comm.rank != 0:
            return
        tol = 1e-12 * max(1.0, abs(float(t)))
        if any(abs(s - float(t)) <= tol for s, _ in self.earlier):
            return  # the restart's own time: the earlier run's grid stays (it was written
            # from the solve itself; a restored state lacks what only a solve gives, such as
            # contact reactions)
        _room_for(self.h5path, sum(v.nbytes + 2048 for *_, v in gathered) + 16384)
        attributes = []
        f = h5_open(self.h5path, "a")
        try:
            for name, center, kind, values in gathered:
                path = f"/Function/{name}/{self.count}"
                f.create_dataset(path, data=values)
                attributes.append((name, center, kind, path, values.shape))
            f.close()
        except BaseException:
            _keep_failed(f)
            raise
        self.count += 1
        grid = grid_element(self.order, self.h5path.name, t, attributes)
        self.grids = [(s, g, x) for s, g, x in self.grids if abs(s - float(t)) > tol]
        self.grids.append((float(t), grid, grid_xml(grid)))
        atomic_write(self.index, index_xml(self._earlier_xml + [x for _, _, x in self.grids]))
