"""Non-finite numbers and meshes that cannot fit are refused before any work: one line on
stderr, exit status 2, no traceback, nothing written."""
import pytest

from conftest import run_cli

BAD = [
    (["--k", "inf"], "--k must be a finite number"),
    (["--T", "nan"], "--T must be a finite number"),
    (["--set", "kappa=nan"], "parameter kappa must be a finite number"),
    (["--set", "E=-inf"], "parameter E must be a finite number"),
    (["--n", "100000000"], "GiB available"),
]


@pytest.mark.parametrize("args,message", BAD, ids=[" ".join(a) for a, _ in BAD])
def test_refused_before_any_work(tmp_path, args, message):
    out = tmp_path / "out"
    proc = run_cli(["run", "2.1-ex1", *args, "--out", out], check=False, timeout=60)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], proc.stderr
    assert "Traceback" not in proc.stderr + proc.stdout
    assert not out.exists() or not any(out.iterdir())


def test_huge_gmsh_mesh_refused(tmp_path):
    proc = run_cli(["run", "2.1-ex3", "--h", "1e-5", "--out", tmp_path / "o"], check=False, timeout=60)
    assert proc.returncode == 2 and "GiB" in proc.stderr and len(proc.stderr.strip().splitlines()) == 1


def test_inf_allowed_where_it_means_none(tmp_path):
    """L_trunc = inf is the documented 'no truncation' and stays accepted."""
    proc = run_cli(["run", "2.1-ex1", "--n", "5", "--k", "0.5", "--set", "L_trunc=inf",
                    "--no-figures", "--quiet", "--out", tmp_path / "o"], check=False, timeout=120)
    assert proc.returncode == 0, proc.stderr
