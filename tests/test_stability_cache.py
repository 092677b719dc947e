"""The eigensolved stability limit is kept on disk: a second process on the same problem reads
it and does not eigensolve; the folder comes from the environment (never the run folder);
concurrent writers and damaged files leave a usable cache."""
import json
import os
import subprocess
import sys
import threading

import pytest
from mpi4py import MPI

from damage_dolfinx.numerics import stability_cache

#: one process: the 3.1 Ex. 1 matrices at n = 6 (literal reading: with contact stiffness),
#: the eigensolve forced (k above the bound is not needed: exact_estimates); prints
#: decided_by, k_max and the number of eigensolves of this process
SCRIPT = """
import ufl
from mpi4py import MPI
from damage_dolfinx.catalogue import examples
from damage_dolfinx.geometries import GAMMA_C
from damage_dolfinx.numerics import stability, stability_bound
st = examples.get("3.1-ex1", "literal").build(MPI.COMM_WORLD, n=6, k=0.01, T=0.01,
                                              overrides={"stability_check": "off"})
ds = ufl.Measure("ds", domain=st.mesh, subdomain_data=st.data.geometry.facet_tags)
with stability_bound.exact_estimates():
    out = stability.estimate_stability(st.v.function_space, st.params.E, st.params.nu, st.rho,
                                       st.m_visc, st.c_nu, ds(GAMMA_C), st.bcs)
print(out["decided_by"], repr(out["k_max"]), stability.EIGENSOLVES["count"], sep="|")
"""


def run(env):
    proc = subprocess.run([sys.executable, "-c", SCRIPT], env=env, capture_output=True,
                          text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    decided, k_max, count = proc.stdout.strip().splitlines()[-1].split("|")
    return decided, float(k_max), int(count)


def test_second_process_reads_the_disk_cache(tmp_path):
    env = dict(os.environ, DAMAGE_DOLFINX_CACHE_DIR=str(tmp_path / "cache"))
    first = run(env)
    second = run(env)
    print(first, second)
    assert first[0] == "eigensolve" and first[2] == 1
    assert second[0] == "disk cache" and second[2] == 0   # no eigensolve in the second process
    assert second[1] == first[1]
    files = list((tmp_path / "cache" / "stability").glob("*.json"))
    assert len(files) == 1 and not list((tmp_path / "cache" / "stability").glob(".*"))
    # a damaged file is ignored: the eigensolve runs again and rewrites it
    files[0].write_text("{not json")
    third = run(env)
    assert third[0] == "eigensolve" and third[1] == first[1]
    assert json.loads(files[0].read_text())["k_max"] == first[1]
    # off: no disk cache at all
    off = run(dict(env, DAMAGE_DOLFINX_CACHE_DIR="off"))
    assert off[0] == "eigensolve" and off[2] == 1


def test_cache_folder_from_the_environment(monkeypatch, tmp_path):
    monkeypatch.delenv(stability_cache.ENV, raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert stability_cache.directory() == tmp_path / "xdg" / "damage-dolfinx" / "stability"
    monkeypatch.setenv("XDG_CACHE_HOME", "relative/path")  # not absolute: ignored (XDG)
    assert stability_cache.directory() == \
        stability_cache.Path.home() / ".cache" / "damage-dolfinx" / "stability"
    monkeypatch.setenv(stability_cache.ENV, str(tmp_path / "mine"))
    assert stability_cache.directory() == tmp_path / "mine" / "stability"
    monkeypatch.setenv(stability_cache.ENV, "off")
    assert stability_cache.directory() is None


def test_concurrent_writers_leave_one_whole_file(monkeypatch, tmp_path):
    monkeypatch.setenv(stability_cache.ENV, str(tmp_path))
    value = {"omega2_max": 4.0, "k_max": 0.5, "k_max_proportional_formula": 1.0,
             "k_suggested": 0.4, "eigen_method": "slepc"}
    errors = []

    def write(i):
        try:
            for _ in range(50):
                assert stability_cache.save("abc", dict(value, k_max=0.5 + i * 1e-3),
                                            MPI.COMM_SELF)
                got = stability_cache.load("abc", MPI.COMM_SELF)
                assert got is not None and got["k_max"] in [0.5 + j * 1e-3 for j in range(4)]
        except Exception as exc:  # noqa: BLE001 -- reported below
            errors.append(exc)
    threads = [threading.Thread(target=write, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    assert sorted(p.name for p in (tmp_path / "stability").iterdir()) == ["abc.json"]


def test_unwritable_folder_means_no_disk_cache(monkeypatch, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    monkeypatch.setenv(stability_cache.ENV, str(blocker))  # a file: no folder below it
    assert stability_cache.save("abc", {"k_max": 1.0}, MPI.COMM_SELF) is False
    assert stability_cache.load("abc", MPI.COMM_SELF) is None


@pytest.mark.parametrize("bad", [{"k_max": "x"}, {"k_max": float("nan")}, []])
def test_invalid_content_is_ignored(monkeypatch, tmp_path, bad):
    monkeypatch.setenv(stability_cache.ENV, str(tmp_path))
    (tmp_path / "stability").mkdir()
    content = bad if not isinstance(bad, dict) else {
        "omega2_max": 1.0, "k_max_proportional_formula": 1.0, "k_suggested": 1.0,
        "format": stability_cache.FORMAT, **bad}
    (tmp_path / "stability" / "abc.json").write_text(json.dumps(content))
    assert stability_cache.load("abc", MPI.COMM_SELF) is None
