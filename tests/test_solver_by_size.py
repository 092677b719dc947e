"""The solver choice by size (numerics/scalable.py): above ``-<prefix>amg_min_dofs`` the 2-D
elasticity (2.1), velocity (3.1) and damage PDE (2.1) systems are solved by CG + AMG, and the
answer equals the direct solvers' to the AMG tolerance (rtol 1e-10), serially and on 2 ranks."""
import json

import numpy as np
import pytest

from conftest import run_cli

#: lowers the threshold of every system of the rule to 0 unknowns: AMG at any size
AMG_OPTIONS = {"2.1-ex1": ["-mech_amg_min_dofs", "0", "-damage_amg_min_dofs", "0"],
               "3.1-ex1": ["-mech_amg_min_dofs", "0"]}
ARGS = {"2.1-ex1": ["--n", "10", "--k", "0.05", "--T", "0.2"],
        "3.1-ex1": ["--n", "10", "--k", "0.01", "--T", "0.05", "--set", "stability_check=off"]}


def _fields(out):
    """u and zeta of a run, ordered by coordinates (any number of ranks)."""
    data = np.load(out / "fields_final.npz")
    fields = {}
    for name in ("u", "zeta"):
        X = np.round(np.asarray(data[name + "_coords"], float), 10)
        order = np.lexsort(X.T[::-1])
        fields[name] = np.asarray(data[name]).reshape(len(X), -1)[order]
    return fields


def _run(example, out, extra=(), np_=1):
    run_cli(["run", example, *ARGS[example], "--no-figures", "--quiet", "--checkpoint-seconds",
             "0", "--out", out, *extra], np_=np_)
    rows = (out / "history.csv").read_text().splitlines()
    header = rows[0].split(",")
    its = [dict(zip(header, r.split(",")))["mech_its"] for r in rows[2:]]
    return _fields(out), [int(float(i)) for i in its], json.loads((out / "summary.json").read_text())


@pytest.mark.parametrize("example", ["2.1-ex1", "3.1-ex1"])
def test_amg_above_the_threshold_gives_the_direct_answer(example, tmp_path):
    direct, direct_its, _ = _run(example, tmp_path / "direct")
    for np_ in (1, 2):
        amg, amg_its, summary = _run(example, tmp_path / f"amg{np_}", AMG_OPTIONS[example], np_)
        assert summary["mpi_size"] == np_
        # the switch happened: a factorisation solves in 1-3 iterations at this size, CG + AMG
        # needs several times more
        assert min(amg_its) > max(direct_its)
        for name in ("u", "zeta"):
            diff = np.abs(amg[name] - direct[name]).max() / np.abs(direct[name]).max()
            assert diff < 1e-8, (example, np_, name, diff)


@pytest.mark.parametrize("options, name", [
    (["-mech_amg_min_dofs", "many"], "-mech_amg_min_dofs"),
    (["-mech_amg_min_dofs", "0", "-mech_amg_rebuild_its", "-3"], "-mech_amg_rebuild_its")])
def test_bad_threshold_is_refused(tmp_path, options, name):
    proc = run_cli(["run", "2.1-ex1", "--n", "5", "--T", "0.02", "--no-figures", "--quiet",
                    "--out", tmp_path / "bad", *options], check=False)
    assert proc.returncode == 2
    assert f"{name} must be a whole number" in proc.stderr
