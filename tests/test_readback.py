"""Read-back that never lies: read_run refuses times outside the stored range and names a
damaged file in one clear line, whatever is damaged (h5, XML, JSON, CSV, NPZ)."""
import math
import shutil

import numpy as np
import pytest

from conftest import run_cli

ARGS = ["run", "2.4-ex1", "--n", "6", "--k", "0.01", "--T", "0.05", "--no-figures", "--quiet"]


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    out = tmp_path_factory.mktemp("readback") / "run"
    run_cli(ARGS + ["--out", out])
    return out


def _copy(folder, tmp_path):
    target = tmp_path / "run"
    shutil.copytree(folder, target)
    return target


@pytest.mark.parametrize("t", [100.0, -1.0, 0.05 + 1e-6, math.nan, math.inf, -math.inf, True,
                               "0.01"])
def test_time_outside_the_stored_range_is_refused(folder, t):
    import damage_dolfinx as dd
    run = dd.read_run(folder)
    with pytest.raises(dd.InputError) as info:
        run.field("zeta", t=t)
    message = str(info.value)
    assert "\n" not in message and "0 to 0.05" in message, message
    with pytest.raises(dd.InputError):
        run.integral("zeta", t=t)


def test_times_in_the_range_are_read(folder):
    import damage_dolfinx as dd
    run = dd.read_run(folder)
    assert np.allclose(run.times, np.arange(6) * 0.01)
    assert run.field("zeta", t=0.03).t == pytest.approx(0.03)
    assert run.field("zeta", t=0.031).t == pytest.approx(0.03)  # the nearest stored time
    assert run.field("zeta", t=np.float64(0.05)).t == pytest.approx(0.05)
    assert run.field("zeta").t == pytest.approx(0.05)  # default: the last


def _truncate(path, keep=0.5):
    data = path.read_bytes()
    path.write_bytes(data[:int(len(data) * keep)])


DAMAGES = {
    "truncated h5": ("fields.h5", lambda p: _truncate(p), "field"),
    "h5 zeroed": ("fields.h5", lambda p: p.write_bytes(b"\0" * p.stat().st_size), "field"),
    "h5 removed": ("fields.h5", lambda p: p.unlink(), "field"),
    "xml cut": ("fields.xdmf", lambda p: _truncate(p), "field"),
    "xml not xdmf": ("fields.xdmf", lambda p: p.write_text("<Xdmf><Domain><Grid "
                                                           "CollectionType='Temporal'><Grid>"
                                                           "</Grid></Grid></Domain></Xdmf>"),
                     "field"),
    "json cut": ("summary.json", lambda p: _truncate(p), "open"),
    "json a list": ("summary.json", lambda p: p.write_text("[1, 2]"), "open"),
    "csv binary": ("history.csv", lambda p: p.write_bytes(b"t,u\n\0\xff\xfe\x00,1\n"), "open"),
    "csv no header": ("history.csv", lambda p: p.write_text("1,2,3\n4,5,6\n"), "open"),
    "npz cut": ("fields_final.npz", lambda p: _truncate(p), "final"),
    "npz not a zip": ("fields_final.npz", lambda p: p.write_bytes(b"PK\x03\x04garbage"), "final"),
}


@pytest.mark.parametrize("damage", sorted(DAMAGES))
def test_damaged_file_gives_one_clear_error_naming_it(folder, tmp_path, damage):
    import damage_dolfinx as dd
    name, spoil, when = DAMAGES[damage]
    run_folder = _copy(folder, tmp_path)
    spoil(run_folder / name)
    with pytest.raises(dd.InputError) as info:
        run = dd.read_run(run_folder)
        if when == "field":
            run.field("zeta", t=0.02)
        elif when == "final":
            run.final
    message = str(info.value)
    print(f"{damage}: {message}")
    assert name in message and "\n" not in message, message
    assert "Traceback" not in message and len(message) < 400, message


def test_an_undamaged_copy_reads_the_same(folder, tmp_path):
    """The planted damages above are the only difference: the copy itself reads back fine."""
    import damage_dolfinx as dd
    a, b = dd.read_run(folder), dd.read_run(_copy(folder, tmp_path))
    assert np.array_equal(a.field("zeta", 0.02).values, b.field("zeta", 0.02).values)
    assert set(b.final) == set(a.final) and len(b.history["t"]) == 6
