"""dd.steps: the run in the caller's own loop. In the ``with`` form an exception of the loop body
is a failure (summary.json "failed" with the error, one outcome on every rank, no rank left
waiting); a ``break`` is a stop, in either form."""
import json
import subprocess
import sys
import textwrap
import time

import pytest

import damage_dolfinx as dd
from conftest import ENV, tool_lines

CASE = dict(n=5, k=0.25, T=1.0, progress=False, figures=False)


def summary(out):
    return json.loads((out / "summary.json").read_text())


def test_a_raise_in_the_with_body_is_a_failure(tmp_path):
    out = tmp_path / "o"
    with pytest.raises(ZeroDivisionError):
        with dd.steps("2.1-ex1", out, **CASE) as run:
            for step in run:
                if step.n == 2:
                    1 / 0
    s = summary(out)
    assert s["status"] == "failed", s
    assert s["error"].startswith("ZeroDivisionError: division by zero"), s["error"]


def test_a_break_in_the_with_body_is_a_stop(tmp_path):
    out = tmp_path / "o"
    with dd.steps("2.1-ex1", out, **CASE) as run:
        for step in run:
            if step.n == 2:
                break
    s = summary(out)
    assert (s["status"], s["steps_done"]) == ("stopped", 2), s
    assert (out / "checkpoint.json").is_file()  # restart=True continues it


def test_the_with_form_runs_to_the_end(tmp_path):
    out = tmp_path / "o"
    with dd.steps("2.1-ex1", out, **CASE) as run:
        seen = [step.n for step in run]
    assert seen == [0, 1, 2, 3, 4]
    assert summary(out)["status"] == "completed" and run.summary["status"] == "completed"


def test_a_break_in_a_plain_loop_is_a_stop(tmp_path):
    out = tmp_path / "o"
    for step in dd.steps("2.1-ex1", out, **CASE):
        if step.n == 1:
            break
    s = summary(out)
    assert (s["status"], s["steps_done"]) == ("stopped", 1), s


SCRIPT = textwrap.dedent('''
    import sys
    from mpi4py import MPI
    import damage_dolfinx as dd

    with dd.steps("2.1-ex1", sys.argv[1], n=5, k=0.25, T=1.0, progress=False,
                  figures=False) as run:
        for step in run:
            if step.n == 2 and MPI.COMM_WORLD.rank == 1:
                raise RuntimeError("the loop body fails on rank 1")
''')


def test_a_raise_on_rank_1_only_in_the_with_body_ends_both_ranks(tmp_path):
    script, out = tmp_path / "mine.py", tmp_path / "o"
    script.write_text(SCRIPT)
    start = time.monotonic()
    proc = subprocess.run(["mpirun", "-n", "2", sys.executable, str(script), str(out)],
                          capture_output=True, text=True, env=ENV, timeout=60)
    assert time.monotonic() - start < 30, proc.stderr
    assert proc.returncode == 3, proc.stderr
    lines = tool_lines(proc.stderr)
    assert len(lines) == 1 and "rank 1" in lines[0] and "RuntimeError" in lines[0], proc.stderr
    s = summary(out)
    assert s["status"] == "failed" and "RuntimeError" in s["error"], s


def test_on_step_stops_the_run_after_a_few_steps(tmp_path):
    """A stop after the first step is recorded as such (it stayed "running" when the stop was
    caught in a generator nested in the run's own)."""
    out = tmp_path / "o"
    s = dd.run("2.1-ex1", out, on_step=lambda step: step.n == 2, **CASE)
    assert (s["status"], s["steps_done"]) == ("stopped", 2)
    assert summary(out)["status"] == "stopped"


PLAIN = textwrap.dedent('''
    import sys
    from mpi4py import MPI
    import damage_dolfinx as dd

    out, how = sys.argv[1], sys.argv[2]
    for step in dd.steps("2.1-ex1", out, n=5, k=0.25, T=1.0, progress=False, figures=False):
        if step.n == 2 and (how == "break" or MPI.COMM_WORLD.rank == 1):
            if how == "break":
                break
            raise RuntimeError("the loop body fails on rank 1")
''')


@pytest.mark.parametrize("how", ["raise", "break"])
def test_a_plain_loop_on_2_ranks_never_leaves_a_rank_waiting(tmp_path, how):
    """Without the with block a raise cannot be told from a break; the ranks agree after each
    step whether their loops went on: a loop left on one rank only ends the others (failed),
    a break on every rank is a stop."""
    script, out = tmp_path / "mine.py", tmp_path / "o"
    script.write_text(PLAIN)
    start = time.monotonic()
    proc = subprocess.run(["mpirun", "-n", "2", sys.executable, str(script), str(out), how],
                          capture_output=True, text=True, env=ENV, timeout=60)
    assert time.monotonic() - start < 30, proc.stderr
    s = summary(out)
    if how == "break":
        assert proc.returncode == 0, proc.stderr
        assert (s["status"], s["steps_done"]) == ("stopped", 2), s
    else:
        assert proc.returncode != 0
        assert s["status"] == "failed" and "ended on rank(s) 1 at step 2" in s["error"], s


def test_a_second_run_into_a_folder_this_process_is_writing_is_refused(tmp_path):
    """A notebook that runs a cell again while its earlier dd.steps is still open: the second
    run into that folder is refused, saying the holder is this process, and the first goes on
    to complete (nothing of it is replaced)."""
    out = tmp_path / "o"
    first = dd.steps("2.1-ex1", out, **CASE)
    it = iter(first)
    assert [next(it).n, next(it).n] == [0, 1]
    with pytest.raises(dd.InputError, match="in this same process .a dd.steps not yet closed."):
        dd.run("2.1-ex1", out, overwrite=True, **CASE)
    assert [step.n for step in it] == [2, 3, 4]
    s = summary(out)
    assert s["status"] == "completed" and s["steps_done"] == 4, s
