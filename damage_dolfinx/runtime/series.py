"""One time series per run: the ``fields.xdmf`` index across restarts, and reading it back.

A run writes ``fields.xdmf`` + ``fields.h5`` (series_file.py: one grid per output time holding
every field, the mesh in a rank-independent node order). A restart from step N writes its own
segment ``fields_from_stepN.h5``, and after every output time rank 0 rewrites ``fields.xdmf``
(atomically) as the index of the whole run: the time grids t <= t_N of the previous index, then
every later time of the new segment (t_N itself too when the previous index lacks it). Every
segment holds the same mesh, node for node, whatever the number of ranks, so one mesh serves
the whole series; each grid still names its own segment's mesh datasets, ``<segment>.h5:/path``
relative to the folder (the folder can be moved). After any
number of restarts on any number of ranks, ``fields.xdmf`` is one series from t = 0 to the last
output time, each time once; plain XDMF 3, read by ParaView, meshio and ``Series`` here (h5py).
Folders written by earlier versions (one temporal collection per field, DOLFINx's writer) are
read too: their grids are merged time by time.
"""
from __future__ import annotations

import copy
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from damage_dolfinx.core.parameters import InputError
from damage_dolfinx.runtime.series_file import LAYOUT, h5_open

#: what summary.json says about the mechanism (outputs.xdmf_series)
MECHANISM = ("fields.xdmf is the index of the whole run, one grid per output time with every "
             "field, nodes in the mesh's input order (the same on any number of ranks): a "
             "restart from step N writes its own fields_from_stepN.h5 and fields.xdmf is "
             "rewritten to reference the datasets of every segment (relative paths), with the "
             "times after t_N taken from the newest segment only")


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


def _time_key(t: float) -> float:
    return float(f"{t:.12g}")


def parse(path):
    """The root element of an XDMF file; InputError naming the file when it does not parse."""
    try:
        return ET.parse(path).getroot()
    except ET.ParseError as exc:
        raise InputError(f"cannot read {str(path)!r}: not valid XML ({exc}): the file is "
                         "damaged or was cut short") from None
    except OSError as exc:
        raise InputError(f"cannot read {str(path)!r}: {exc.strerror or exc}") from None


def time_grids(path, root=None) -> list:
    """[(t, Grid)] of an XDMF file in time order, one grid per time holding every field's
    Attribute and its own Topology/Geometry (XIncludes of the file's mesh replaced by copies;
    the one-collection-per-field layout of earlier versions merged time by time)."""
    root = parse(path) if root is None else root
    mesh = _mesh_parts(root)
    merged = {}
    try:
        for collection in root.iter("Grid"):
            if collection.get("CollectionType") != "Temporal":
                continue
            for grid in collection.findall("Grid"):
                t = float(grid.find("Time").get("Value"))
                key = _time_key(t)
                if key not in merged:
                    out = ET.Element("Grid", {"Name": "fields", "GridType": "Uniform"})
                    for child in grid:
                        if _is_xinclude(child.tag):
                            out.extend(copy.deepcopy(part) for part in mesh)
                        elif child.tag in ("Topology", "Geometry", "Time"):
                            out.append(copy.deepcopy(child))
                    merged[key] = (t, out)
                merged[key][1].extend(copy.deepcopy(a) for a in grid.findall("Attribute"))
    except (AttributeError, TypeError, ValueError) as exc:
        raise InputError(f"cannot read {str(path)!r}: not an XDMF time series ({exc})") from None
    return sorted(merged.values(), key=lambda item: item[0])


def earlier_grids(index, since: float) -> list:
    """The time grids of the index file ``index`` with t <= ``since`` (the restart's time: its
    grid, when the earlier run wrote it, is kept; none if the file is absent or does not
    parse)."""
    try:
        grids = time_grids(index)
    except InputError:
        return []
    tol = 1e-12 * max(1.0, abs(since))
    return [(t, g) for t, g in grids if t <= since + tol]


def data_files(grids) -> list:
    """The .h5 files that time grids [(t, Grid)] reference, in order of first use."""
    names = []
    for item in (item for _, g in grids for item in g.iter("DataItem")):
        name = (item.text or "").strip().split(":", 1)[0]
        if name and name not in names:
            names.append(name)
    return names


# ------------------------------------------------------------------ reading back (h5py)
#: a read that meets a file in the middle of a write is tried again this often (0.1 s apart)
READ_TRIES = 5


def _dataset(folder, item):
    """The array a DataItem names, read without HDF5 file locking (a run writing the file is
    never locked out); InputError naming the file when it is damaged, cut short or lacks the
    dataset (after READ_TRIES tries: a writer may be adding a dataset at this moment)."""
    import time
    try:
        name, key = item.text.strip().split(":", 1)
    except (AttributeError, ValueError):
        raise InputError(f"a DataItem of the series names no HDF5 dataset "
                         f"({(item.text or '').strip()!r})") from None
    path = Path(folder) / name
    for attempt in range(READ_TRIES):
        try:
            with h5_open(path, "r") as f:
                return np.asarray(f[key][()])
        except FileNotFoundError:
            raise InputError(f"cannot read {str(path)!r}: no such file (the series "
                             "references it)") from None
        except (OSError, KeyError, ValueError, RuntimeError) as exc:
            error = exc
            time.sleep(0.1)
    what = f"no dataset {key}" if isinstance(error, KeyError) else \
        str(error).splitlines()[0] if str(error) else type(error).__name__
    raise InputError(f"cannot read {str(path)!r}: {what}: the file is damaged or was cut "
                     "short") from None


def _tensor_2d_columns(values) -> list:
    """The columns of a 2 x 2 tensor written as 9 components: DOLFINx 0.5 pads it as a 3 x 3
    matrix (xx, xy, 0, yx, yy, 0, 0, 0, 0), later versions append the zeros (xx, xy, yx, yy, 0,
    ...); told apart by where the zeros are (folders of earlier versions only: series_file.py
    always writes 3 x 3)."""
    zero = ~np.any(values != 0.0, axis=0)
    if zero[2] and zero[5:].all() and not zero[4]:
        return [0, 1, 3, 4]
    if zero[4:].all():
        return [0, 1, 2, 3]
    return [0, 1, 3, 4]


def checked_time(t, times, what) -> float:
    """``t`` as a float within [times[0], times[-1]]; InputError (one line, naming the range)
    for a bool, a non-number, NaN, an infinity or a time outside the stored range."""
    lo, hi = times[0], times[-1]
    span = f"the stored times of {what} are {lo:.6g} to {hi:.6g} ({len(times)} times)"
    if isinstance(t, bool) or not isinstance(t, (int, float, np.integer, np.floating)):
        raise InputError(f"t must be a number, got {t!r}; {span}")
    t = float(t)
    tol = 1e-9 * max(1.0, abs(lo), abs(hi))
    if not np.isfinite(t) or t < lo - tol or t > hi + tol:
        raise InputError(f"t = {t!r} is outside the stored range: {span}")
    return t


class Series:
    """A run's ``fields.xdmf`` read with h5py: ``times``, ``names`` and ``field(name, t)``."""

    def __init__(self, path):
        self.path = Path(path)
        root = parse(self.path)
        domain = root.find("Domain")
        self.layout = domain.get("Name") == LAYOUT if domain is not None else False
        self.grids = time_grids(self.path, root)
        self.times = [t for t, _ in self.grids]
        self.names = []
        for _, grid in self.grids:
            for a in grid.findall("Attribute"):
                if a.get("Name") not in self.names:
                    self.names.append(a.get("Name"))
        if not self.grids:
            raise InputError(f"{str(self.path)!r} holds no output time yet")

    def _grid(self, name, t):
        """(t found, grid, attribute) of ``name`` at the stored time nearest ``t`` (default:
        the last), ``t`` checked against the stored range."""
        if name not in self.names:
            raise KeyError(f"no field {name!r} in {self.path.name}; fields: "
                           f"{', '.join(self.names)}")
        steps = [(s, g, a) for s, g in self.grids for a in g.findall("Attribute")
                 if a.get("Name") == name]
        t = steps[-1][0] if t is None else checked_time(t, [s for s, _, _ in steps],
                                                        f"{name} in {self.path.name}")
        return min(steps, key=lambda s: abs(s[0] - t))

    def _read(self, grid, path):
        node = grid.find(path)
        if node is None:
            raise InputError(f"cannot read {str(self.path)!r}: a grid has no {path}")
        return _dataset(self.path.parent, node)

    def field(self, name, t=None):
        """(coords, values) of ``name`` at the stored time nearest ``t`` (default: the last;
        a time outside the stored range is refused), in the rank-independent order of
        fields_final.npz (sorted by x, then y (then z)); cell fields at the cell midpoints;
        2-D vectors without XDMF's zero third component."""
        t_found, grid, attribute = self._grid(name, t)
        geometry = self._read(grid, "Geometry/DataItem")
        values = _dataset(self.path.parent, attribute.find("DataItem"))
        if values.ndim == 1:
            values = values[:, None]
        gdim = geometry.shape[1]
        if attribute.get("Center") == "Cell":
            topology = self._read(grid, "Topology/DataItem").astype(np.int64)
            coords = geometry[topology].mean(axis=1)
        else:
            coords = geometry
        if attribute.get("AttributeType") == "Vector" and values.shape[1] == 3 and gdim == 2:
            values = values[:, :2]
        if attribute.get("AttributeType") == "Tensor" and values.shape[1] == 9 and gdim == 2:
            values = values[:, [0, 1, 3, 4] if self.layout else _tensor_2d_columns(values)]
        key = np.round(coords, 10)
        key, first = np.unique(key, axis=0, return_index=True)  # shared nodes written once each
        coords, values = coords[first], values[first]
        order = np.lexsort(key.T[::-1])
        return coords[order], values[order], t_found

    def integral(self, name, t=None):
        """int_Omega f dx of field ``name`` (a node field: P1, exact cell by cell as |T| times
        the mean of its vertex values on triangles and tetrahedra; a cell field: sum |T| f_T),
        per component, at the stored time nearest ``t`` (checked as in ``field``)."""
        _, grid, attribute = self._grid(name, t)
        x = self._read(grid, "Geometry/DataItem")
        cells = self._read(grid, "Topology/DataItem").astype(np.int64)
        values = _dataset(self.path.parent, attribute.find("DataItem"))
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
