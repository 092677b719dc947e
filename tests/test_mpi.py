"""Parallel coverage: unit tests under `mpirun -n 2`, and a convergence study that gives the
same error table in serial and on two ranks."""
import json
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import ENV, run_cli

HERE = Path(__file__).parent


@pytest.mark.mpi
def test_unit_tests_pass_on_two_ranks():
    cmd = ["mpirun", "-n", "2", sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
           str(HERE / "test_transfer.py"), str(HERE / "test_damage_step.py")]
    proc = subprocess.run(cmd, env=ENV, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout + proc.stderr


@pytest.mark.mpi
def test_convergence_table_serial_equals_two_ranks(tmp_path):
    args = ["converge", "2.1-ex1", "--ref-n", "20", "--ref-k", "0.05", "--n", "5", "10",
            "--k", "0.1", "--T", "0.5", "--quiet"]
    run_cli(args + ["--out", tmp_path / "s"])
    # the layout with the reference on all ranks (the default, one rank, is tested below)
    run_cli(args + ["--reference-ranks", "all", "--out", tmp_path / "p"], np_=2)
    s = json.loads((tmp_path / "s" / "summary.json").read_text())
    p = json.loads((tmp_path / "p" / "summary.json").read_text())
    assert p["mpi_size"] == 2
    for rs, rp in zip(s["errors"], p["errors"]):
        assert (rs["n"], rs["k"]) == (rp["n"], rp["k"])
        assert rp["error"] == pytest.approx(rs["error"], rel=1e-8)
    # the error decreases with h + k (the table is not trivially zero)
    errs = [r["error"] for r in s["errors"]]
    assert errs[0] > errs[1] > 0
    for name in ("errors.csv", "errors.md", "convergence.png"):
        assert (tmp_path / "p" / name).exists()


@pytest.mark.mpi
def test_convergence_reference_on_one_rank(tmp_path):
    """The layout with the reference serially on rank 0 and the cells on the other ranks
    (--reference-ranks 1) gives the table of the serial study, on 2 and 3 ranks; the
    3.3 reference uses the serial-only zeta-linear matrices there."""
    args = ["converge", "3.3-ex1", "--ref-n", "16", "--ref-k", "0.002", "--n", "4", "8",
            "--k", "0.01", "0.004", "--T", "0.1", "--quiet"]
    run_cli(args + ["--out", tmp_path / "s"])
    s = json.loads((tmp_path / "s" / "summary.json").read_text())
    for np_ in (2, 3):
        run_cli(args + ["--reference-ranks", "1", "--out", tmp_path / f"p{np_}"], np_=np_)
        p = json.loads((tmp_path / f"p{np_}" / "summary.json").read_text())
        assert p["mpi_size"] == np_ and p["reference"]["ranks"] == 1
        owners = {owner for _, _, owner in p["serial_cells"]["rank_of_cell"]}
        assert owners == set(range(1, np_))  # rank 0 runs the reference alone
        for rs, rp in zip(s["errors"], p["errors"]):
            assert (rs["n"], rs["k"]) == (rp["n"], rp["k"])
            assert rp["error"] == pytest.approx(rs["error"], rel=1e-8)
            assert rp["error_at_T"] == pytest.approx(rs["error_at_T"], rel=1e-8)
    assert s["errors"][0]["error"] > s["errors"][-1]["error"] > 0


@pytest.mark.mpi
@pytest.mark.parametrize("args", [
    ["2.4-ex2", "--n", "8", "--k", "0.02", "--T", "0.2"],
    ["3.1-ex2", "--n", "5", "--T", "0.04"],
    ["3.2-ex3", "--n", "5", "--T", "0.05"],
    ["3.3-ex2", "--n", "4", "--k", "2.5e-4", "--T", "0.05", "--set", "initial_damage=b"],
], ids=lambda a: a[0])
def test_remaining_examples_serial_equals_two_ranks(tmp_path, args):
    """Every catalogue example gives the same fields on 1 and 2 ranks (the others are checked
    in their own test files)."""
    from conftest import serial_and_two_ranks
    serial_and_two_ranks(tmp_path, ["run", *args, "--no-figures", "--quiet"])
