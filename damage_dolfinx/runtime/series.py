"""One time series per run: the ``fields.xdmf`` index across restarts, and reading it back.

A run that is never restarted writes ``fields.xdmf`` + ``fields.h5`` with DOLFINx's XDMFFile.
A restart from step N writes its own segment, ``fields_from_stepN.xdmf`` + ``.h5`` (DOLFINx again:
the mesh may be partitioned differently on another number of ranks, so each segment keeps its own
mesh datasets), and after every output time rank 0 rewrites ``fields.xdmf`` (atomically) as the
index of the whole run: the time steps t < t_N of the previous index, then every time step of the
new segment. Each time step of the index names its own mesh (``Topology``/``Geometry`` copied
from its segment instead of DOLFINx's XInclude of the file's first mesh), and every dataset is
referenced as ``<segment>.h5:/path``, relative to the folder, so the folder can be moved. After
any number of restarts on any number of ranks, ``fields.xdmf`` is one series from t = 0 to the
last output time, each time once; plain XDMF 3, read by ParaView and by ``read_series`` here
(h5py), on every DOLFINx version (only DOLFINx's own writer is used for the heavy data).
"""
from __future__ import annotations

import copy
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

#: what summary.json says about the mechanism (outputs.xdmf_series)
MECHANISM = ("fields.xdmf is the index of the whole run: a restart from step N writes its own "
             "fields_from_stepN.xdmf/.h5 and fields.xdmf is rewritten to reference the datasets "
             "of every segment (relative paths), with the times from t_N on taken from the newest "
             "segment only")

def _is_xinclude(tag) -> bool:
    """An XInclude element, whatever namespace URI the writer declared (DOLFINx 0.5 writes
    http://www.w3.org/2001/XInclude, 0.9 and later https://...)."""
    return isinstance(tag, str) and tag.endswith("}include") and "XInclude" in tag


def _mesh_parts(root):
    """Topology and Geometry of the file's first Uniform grid (what DOLFINx's XInclude names)."""
    for grid in root.iter("Grid"):
        if grid.get("GridType") == "Uniform":
            parts = [c for c in grid if c.tag in ("Topology", "Geometry")]
            if parts:
                return parts
    return []


def time_steps(path) -> dict:
    """field name -> [(t, Grid element with its own Topology/Geometry)] of an XDMF file, in
    file order (XIncludes of the file's mesh replaced by copies of it)."""
    root = ET.parse(path).getroot()
    mesh = _mesh_parts(root)
    series = {}
    for collection in root.iter("Grid"):
        if collection.get("CollectionType") != "Temporal":
            continue
        steps = series.setdefault(collection.get("Name"), [])
        for grid in collection.findall("Grid"):
            grid = copy.deepcopy(grid)
            for i, child in enumerate(list(grid)):
                if _is_xinclude(child.tag):
                    grid.remove(child)
                    for j, part in enumerate(mesh):
                        grid.insert(i + j, copy.deepcopy(part))
            steps.append((float(grid.find("Time").get("Value")), grid))
    return series


def earlier_steps(index, before: float) -> dict:
    """The time steps of the index file ``index`` with t < ``before`` (none if it is absent or
    does not parse)."""
    try:
        series = time_steps(index)
    except (OSError, ET.ParseError):
        return {}
    tol = 1e-12 * max(1.0, abs(before))
    return {name: [(t, g) for t, g in steps if t < before - tol] for name, steps in series.items()}


def index_xml(earlier: dict, segment) -> bytes:
    """The index: ``earlier`` (time_steps-like) followed by every time step of ``segment``."""
    seg_root = ET.parse(segment).getroot()
    root = ET.Element("Xdmf", {"Version": "3.0"})
    domain = ET.SubElement(root, "Domain")
    mesh = ET.SubElement(domain, "Grid", {"Name": "mesh", "GridType": "Uniform"})
    mesh.extend(copy.deepcopy(p) for p in _mesh_parts(seg_root))  # the newest segment's mesh
    newer = time_steps(segment)
    for name in list(earlier) + [n for n in newer if n not in earlier]:
        collection = ET.SubElement(domain, "Grid", {"Name": name, "GridType": "Collection",
                                                    "CollectionType": "Temporal"})
        collection.extend(g for _, g in earlier.get(name, []) + newer.get(name, []))
    ET.indent(root, space="  ")
    return b'<?xml version="1.0"?>\n' + ET.tostring(root, encoding="utf-8") + b"\n"


def data_files(steps) -> list:
    """The .h5 files that time steps (time_steps-like) reference, in order of first use."""
    names = []
    items = (item for grids in steps.values() for _, g in grids for item in g.iter("DataItem"))
    for item in items:
        name = (item.text or "").strip().split(":", 1)[0]
        if name and name not in names:
            names.append(name)
    return names


# ------------------------------------------------------------------ reading back (h5py)
def _dataset(folder, item):
    import h5py
    name, key = item.text.strip().split(":", 1)
    with h5py.File(Path(folder) / name, "r") as f:
        return np.asarray(f[key][()])


def _tensor_2d_columns(values) -> list:
    """The columns of a 2 x 2 tensor written as 9 components: DOLFINx 0.5 pads it as a 3 x 3
    matrix (xx, xy, 0, yx, yy, 0, 0, 0, 0), later versions append the zeros (xx, xy, yx, yy, 0,
    ...); told apart by where the zeros are."""
    zero = ~np.any(values != 0.0, axis=0)
    if zero[2] and zero[5:].all() and not zero[4]:
        return [0, 1, 3, 4]
    if zero[4:].all():
        return [0, 1, 2, 3]
    return [0, 1, 3, 4]


class Series:
    """A run's ``fields.xdmf`` read with h5py: ``times``, ``names`` and ``field(name, t)``."""

    def __init__(self, path):
        self.path = Path(path)
        self.steps = time_steps(self.path)
        self.names = list(self.steps)
        self.times = sorted({t for steps in self.steps.values() for t, _ in steps})

    def field(self, name, t=None):
        """(coords, values) of ``name`` at the stored time nearest ``t`` (default: the last),
        in the rank-independent order of fields_final.npz (sorted by x, then y (then z)); cell
        fields at the cell midpoints; 2-D vectors without XDMF's zero third component."""
        if name not in self.steps:
            raise KeyError(f"no field {name!r} in {self.path.name}; fields: "
                           f"{', '.join(self.names)}")
        steps = self.steps[name]
        t = steps[-1][0] if t is None else float(t)
        t_found, grid = min(steps, key=lambda s: abs(s[0] - t))
        folder = self.path.parent
        geometry = _dataset(folder, grid.find("Geometry/DataItem"))
        attribute = grid.find("Attribute")
        values = _dataset(folder, attribute.find("DataItem"))
        if values.ndim == 1:
            values = values[:, None]
        gdim = geometry.shape[1]
        if attribute.get("Center") == "Cell":
            topology = _dataset(folder, grid.find("Topology/DataItem")).astype(np.int64)
            coords = geometry[topology].mean(axis=1)
        else:
            coords = geometry
        if attribute.get("AttributeType") == "Vector" and values.shape[1] == 3 and gdim == 2:
            values = values[:, :2]
        if attribute.get("AttributeType") == "Tensor" and values.shape[1] == 9 and gdim == 2:
            values = values[:, _tensor_2d_columns(values)]
        key = np.round(coords, 10)
        key, first = np.unique(key, axis=0, return_index=True)  # shared nodes written once each
        coords, values = coords[first], values[first]
        order = np.lexsort(key.T[::-1])
        return coords[order], values[order], t_found

    def integral(self, name, t=None):
        """int_Omega f dx of field ``name`` (a node field: P1, exact cell by cell as |T| times
        the mean of its vertex values on triangles and tetrahedra; a cell field: sum |T| f_T),
        per component, at the stored time nearest ``t``."""
        steps = self.steps[name]
        t = steps[-1][0] if t is None else float(t)
        _, grid = min(steps, key=lambda s: abs(s[0] - t))
        folder = self.path.parent
        x = _dataset(folder, grid.find("Geometry/DataItem"))
        cells = _dataset(folder, grid.find("Topology/DataItem")).astype(np.int64)
        attribute = grid.find("Attribute")
        values = _dataset(folder, attribute.find("DataItem"))
        values = values[:, None] if values.ndim == 1 else values
        edges = x[cells[:, 1:]] - x[cells[:, :1]]  # (cells, dim, gdim)
        if edges.shape[1] == 2 and x.shape[1] == 2:
            size = 0.5 * np.abs(edges[:, 0, 0] * edges[:, 1, 1] - edges[:, 0, 1] * edges[:, 1, 0])
        elif edges.shape[1] == 3:
            size = np.abs(np.linalg.det(edges)) / 6.0
        else:
            raise ValueError("integral: triangles and tetrahedra only")
        per_cell = values if attribute.get("Center") == "Cell" else values[cells].mean(axis=1)
        total = size @ per_cell
        if attribute.get("AttributeType") == "Vector" and total.size == 3 and x.shape[1] == 2:
            total = total[:2]
        return total
