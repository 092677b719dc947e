"""Results that open at once: every field of an output time in one grid of fields.xdmf, and one
node numbering for the whole series, so that a reader that takes one mesh for the series
(meshio's TimeSeriesReader, or the independent h5py/XML reader here) gets the right values
after a restart on another number of ranks (serial, then 2 ranks) - compared with read_run and
with an uninterrupted run."""
import shutil
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from conftest import run_cli

ARGS = ["run", "2.4-ex1", "--n", "8", "--k", "0.01", "--no-figures", "--quiet",
        "--write-every", "5"]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    base = tmp_path_factory.mktemp("layout")
    restarted, full = base / "restarted", base / "full"
    run_cli(ARGS + ["--T", "0.5", "--out", restarted])
    run_cli(ARGS + ["--T", "1", "--restart", "--out", restarted], np_=2)
    run_cli(ARGS + ["--T", "1", "--out", full])
    return restarted, full


def one_mesh_series(folder):
    """Independent reader (ElementTree + h5py, nothing of the package): the mesh of the first
    grid for the whole series, and {t: {name: values}} of every grid."""
    import h5py
    root = ET.parse(folder / "fields.xdmf").getroot()
    collections = [g for g in root.iter("Grid") if g.get("CollectionType") == "Temporal"]
    assert len(collections) == 1, "one temporal collection"

    def read(item):
        name, path = item.text.strip().split(":", 1)
        with h5py.File(folder / name, "r") as f:
            return f[path][()]
    grids = collections[0].findall("Grid")
    points = read(grids[0].find("Geometry/DataItem"))
    cells = read(grids[0].find("Topology/DataItem"))
    series = {}
    for grid in grids:
        assert np.array_equal(read(grid.find("Geometry/DataItem")), points)  # one mesh
        assert np.array_equal(read(grid.find("Topology/DataItem")), cells)
        series[float(grid.find("Time").get("Value"))] = {
            a.get("Name"): read(a.find("DataItem")) for a in grid.findall("Attribute")}
    return points, cells, series


def worst_difference(a, b):
    """Largest difference, relative to the field's largest value, over every field and time."""
    worst = {}
    for t in a:
        for name, values in a[t].items():
            scale = max(np.abs(b[t][name]).max(), 1e-300)
            worst[name] = max(worst.get(name, 0.0), np.abs(values - b[t][name]).max() / scale)
    return worst


def test_restarted_series_reads_through_one_mesh(runs):
    import damage_dolfinx as dd
    restarted, full = runs
    summary = dd.read_run(restarted).summary
    assert [r["mpi_size"] for r in summary["restarts"]] == [2]
    assert summary["outputs"]["xdmf_data"] == ["fields.h5", "fields_from_step50.h5"]
    points, cells, series = one_mesh_series(restarted)
    points_f, cells_f, series_f = one_mesh_series(full)
    assert np.array_equal(points, points_f) and np.array_equal(cells, cells_f)
    assert list(series) == list(series_f) and len(series) == 21
    names = {"u", "zeta", "von_mises", "sigma", "contact_pressure", "friction_traction"}
    assert all(set(fields) == names for fields in series.values())  # every field, every time
    worst = worst_difference(series, series_f)
    print("restarted (1 -> 2 ranks) vs uninterrupted, one mesh:",
          {k: f"{v:.1e}" for k, v in worst.items()})
    assert max(worst.values()) < 1e-10
    run = dd.read_run(restarted)
    order = np.lexsort(np.round(points, 10).T[::-1])
    for t in series:
        for name in ("u", "zeta"):
            f = run.field(name, t)
            values = series[t][name].reshape(len(points), -1)[order][:, :f.values.shape[1]]
            assert np.array_equal(f.coords, points[order]) and np.array_equal(values, f.values)
    z = series[0.45]["zeta"]
    print(f"zeta at t = 0.45 (before the restart): [{z.min():.6g}, {z.max():.6g}]")


def test_a_segment_numbered_otherwise_is_caught(runs, tmp_path):
    """Planted: the restart's segment with two nodes swapped (what a rank-dependent numbering
    gives) - the one-mesh comparison must fail."""
    import h5py
    restarted, full = runs
    planted = tmp_path / "planted"
    shutil.copytree(restarted, planted)
    with h5py.File(planted / "fields_from_step50.h5", "a") as f:
        for key in f["Function/zeta"]:
            data = f["Function/zeta"][key][()]
            f["Function/zeta"][key][...] = data[::-1]
    worst = worst_difference(one_mesh_series(planted)[2], one_mesh_series(full)[2])
    assert worst["zeta"] > 1e-3, worst


def test_meshio_reads_every_field_of_every_time(runs):
    meshio = pytest.importorskip("meshio")
    restarted, full = runs
    _, _, series_f = one_mesh_series(full)

    def read(folder):
        reader = meshio.xdmf.TimeSeriesReader(str(folder / "fields.xdmf"))
        points, cells = reader.read_points_cells()
        out = {}
        for k in range(reader.num_steps):
            t, point_data, cell_data = reader.read_data(k)
            out[t] = {**point_data, **{n: v[0] for n, v in cell_data.items()}}
        return points, out
    points, series = read(restarted)
    assert len(series) == 21 and set(series[0.45]) == set(series_f[0.45])
    worst = worst_difference(series, series_f)
    print("meshio: restarted (1 -> 2 ranks) vs uninterrupted:",
          {k: f"{v:.1e}" for k, v in worst.items()})
    assert max(worst.values()) < 1e-10
    import damage_dolfinx as dd  # meshio keeps the files open (HDF5 locking): read_run still reads
    assert dd.read_run(restarted).field("zeta", 0.45).values.size == len(points)
