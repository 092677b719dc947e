"""Bad input is refused before any computation with one clear line (exit status 2)."""
import os

import pytest

from damage_dolfinx import cli


@pytest.mark.parametrize("args, message", [
    (["run", "9.9-ex7"], "unknown example id"),
    (["run", "2.1-ex1", "--set", "zeta_star=1.5"], "zeta_star must lie in (0, 1)"),
    (["run", "2.1-ex1", "--set", "zeta_star=0"], "zeta_star must lie in (0, 1)"),
    (["run", "2.1-ex1", "--set", "zeta0=0.001"], "zeta0 must lie in [zeta_star, 1]"),
    (["run", "2.1-ex1", "--k", "0"], "--k must be > 0"),
    (["run", "2.1-ex1", "--k", "-0.1"], "--k must be > 0"),
    (["run", "2.1-ex1", "--T", "0"], "--T must be > 0"),
    (["run", "2.1-ex1", "--k", "0.3"], "does not divide T"),
    (["run", "2.1-ex1", "--set", "E=-5"], "Young modulus E must be positive"),
    (["run", "2.1-ex1", "--set", "nu=0.5"], "Poisson ratio nu must lie in (-1, 0.5)"),
    (["run", "2.1-ex1", "--set", "kappa=-1"], "kappa must be >= 0"),
    (["run", "2.1-ex1", "--set", "lam_D=abc"], "cannot read 'abc'"),
    (["run", "2.1-ex1", "--set", "bogus=1"], "unknown parameter 'bogus'"),
    (["run", "2.1-ex1", "--n", "0"], "--n must be a whole number >= 1"),
    (["run", "2.1-ex1", "--n", "7"], "multiple of"),
    (["run", "2.1-ex1", "--h", "0.1"], "structured mesh"),
    (["run", "2.1-ex2a", "--n", "10"], "gmsh mesh"),
    (["run", "2.1-ex2a", "--mesh", "/nonexistent/disc.msh"], "does not exist"),
    (["converge", "2.1-ex2a"], "has no mesh family"),
    (["converge", "2.1-ex1", "--ref-n", "40", "--n", "15"], "not nested"),
    (["converge", "2.1-ex1", "--ref-k", "0.003", "--k", "0.01"], "must divide every coarse k"),
    (["run", "2.1-ex1", "--history-every", "0"], "--history-every must be a whole number >= 1"),
    (["run", "3.3-ex3", "--set", "history_every=2.5"], "must be a whole number >= 1"),
    (["run", "3.3-ex3", "--set", "damage_atol_rel=-1"], "damage_atol_rel"),
])
def test_bad_input_is_refused(tmp_path, capsys, args, message):
    out = tmp_path / "out"
    status = cli.main(args + ["--out", str(out)])
    err = capsys.readouterr().err
    assert status == 2
    assert message in err, err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert not (out / "fields.xdmf").exists()


def test_unwritable_output_folder(tmp_path, capsys):
    locked = tmp_path / "locked"
    locked.mkdir()
    os.chmod(locked, 0o500)
    try:
        if os.access(locked, os.W_OK):
            pytest.skip("running as a user that ignores permissions; use a file as parent")
        status = cli.main(["run", "2.1-ex1", "--out", str(locked / "run")])
    finally:
        os.chmod(locked, 0o700)
    assert status == 2 and "not writable" in capsys.readouterr().err


def test_output_under_a_file_is_refused(tmp_path, capsys):
    blocker = tmp_path / "a_file"
    blocker.write_text("x")
    status = cli.main(["run", "2.1-ex1", "--out", str(blocker / "run")])
    assert status == 2 and "not writable" in capsys.readouterr().err


def test_list_names_every_example(capsys):
    assert cli.main(["list"]) == 0
    out = capsys.readouterr().out
    for ex_id in ("2.1-ex1", "2.1-ex2a", "2.1-ex2b"):
        assert ex_id in out


def test_singleton_transports_for_mpi_init_only():
    """A command no MPI launcher started gets Open MPI's singleton transports for MPI_Init
    only (nothing left in its environment); a value set outside is kept."""
    import subprocess
    import sys
    probe = ("import os, damage_dolfinx.cli as c; "
             "print(os.environ.get('OMPI_MCA_pml'), os.environ.get('OMPI_MCA_btl'))")
    env = {k: v for k, v in os.environ.items()
           if k not in ("OMPI_MCA_pml", "OMPI_MCA_btl") and k not in cli._LAUNCHER_VARIABLES}
    out = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True, text=True,
                         check=True).stdout.split()
    assert out == ["None", "None"]
    env["OMPI_MCA_pml"] = "ob1"
    out = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True, text=True,
                         check=True).stdout.split()
    assert out == ["ob1", "None"]


@pytest.mark.parametrize("api, args", [
    ({"k": float("nan")}, ["--k", "nan"]),
    ({"T": float("inf")}, ["--T", "inf"]),
    ({"k": 1e-310}, ["--k", "1e-310"]),
    ({"k": -0.1}, ["--k", "-0.1"]),
    ({"n": 0}, ["--n", "0"]),
    ({"history_every": 0}, ["--history-every", "0"]),
    ({"checkpoint_seconds": float("inf")}, ["--checkpoint-seconds", "inf"]),
    ({"checkpoint_seconds": 1e-320}, ["--checkpoint-seconds", "1e-320"]),
])
def test_one_check_one_message(tmp_path, capsys, api, args):
    """A bad value given through the API and through the command line is refused by the same
    rule (core.validation), with the same words: the command line writes the flag."""
    import traceback
    import damage_dolfinx as dd
    from damage_dolfinx.cli.wording import for_command_line
    with pytest.raises(dd.InputError) as refused:
        dd.run("2.1-ex1", tmp_path / "api", **api)
    where = traceback.extract_tb(refused.value.__traceback__)[-1].filename
    assert where.endswith(os.path.join("core", "validation.py")), where
    status = cli.main(["run", "2.1-ex1"] + args + ["--out", str(tmp_path / "cli")])
    err = capsys.readouterr().err
    assert status == 2
    assert err.strip() == f"damage-dolfinx: error: {for_command_line(str(refused.value))}", err
    assert not (tmp_path / "api").exists() and not (tmp_path / "cli").exists()
