"""Reading a run while it is written never changes the run: a reader polling read_run every
0.05 s (and holding fields.h5 open with HDF5's default file locking, as other tools do) during a
2-rank run; the run's status and every output equal those of the same run without a reader."""
import json
import subprocess
import sys
import textwrap
import time

import numpy as np

from conftest import ENV, run_cli

ARGS = ["run", "2.4-ex1", "--n", "12", "--k", "0.002", "--T", "1", "--no-figures", "--quiet",
        "--write-every", "5"]
#: two 2-rank runs of the same case, both without a reader, differ by round-off (1e-16 to
#: 1e-14 here: the parallel reductions are not bit-reproducible); a reader must change nothing
#: beyond that
TOL = 1e-10


def rel(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    assert np.array_equal(np.isnan(a), np.isnan(b))  # the same values are missing
    a, b = a[~np.isnan(a)], b[~np.isnan(b)]
    return float(np.abs(a - b).max() / max(np.abs(b).max(), 1e-300)) if a.size else 0.0

READER = textwrap.dedent("""
    import json, sys, time
    from pathlib import Path
    import h5py
    import damage_dolfinx as dd
    folder, stop, report = Path(sys.argv[1]), Path(sys.argv[2]), Path(sys.argv[3])
    (report.parent / "reader.ready").touch()  # imports done: the run may start
    polls = reads = fields = held = 0
    errors, seen = [], set()
    while not stop.exists():
        polls += 1
        try:
            run = dd.read_run(folder)
            reads += 1
            if (folder / "fields.xdmf").is_file():
                times = run.times
                f = run.field("zeta", t=times[-1])
                assert f.t == times[-1] and f.values.size
                fields += 1
                seen.add(len(times))
        except dd.InputError as exc:
            errors.append(str(exc))
        try:  # a tool that keeps the file open, with HDF5's default locking
            with h5py.File(folder / "fields.h5", "r"):
                held += 1
                time.sleep(0.05)
        except OSError:
            pass
        time.sleep(0.05)
    report.write_text(json.dumps({"polls": polls, "reads": reads, "field_reads": fields,
                                  "h5_held": held, "errors": errors,
                                  "distinct_time_counts": len(seen)}))
""")


def test_a_polling_reader_never_changes_a_two_rank_run(tmp_path):
    import damage_dolfinx as dd
    alone, watched = tmp_path / "alone", tmp_path / "watched"
    run_cli(ARGS + ["--out", alone], np_=2)
    stop, report = tmp_path / "stop", tmp_path / "reader.json"
    reader = subprocess.Popen([sys.executable, "-c", READER, str(watched), str(stop),
                               str(report)], env=ENV)
    try:
        ready, t0 = tmp_path / "reader.ready", time.time()
        while not ready.exists():  # the reader's own start-up must not eat the run's seconds
            assert reader.poll() is None and time.time() - t0 < 120, "the reader did not start"
            time.sleep(0.05)
        t0 = time.time()
        proc = run_cli(ARGS + ["--out", watched], np_=2, check=False)
        seconds = time.time() - t0
    finally:
        stop.touch()
        reader.wait(timeout=120)
    stats = json.loads(report.read_text())
    print(f"run with a reader: exit {proc.returncode} in {seconds:.1f} s; reader: {stats}")
    assert proc.returncode == 0, proc.stderr
    assert stats["field_reads"] >= 5 and stats["h5_held"] >= 5, stats  # it did read meanwhile
    assert stats["distinct_time_counts"] >= 2, stats  # ... at different moments of the run
    a, b = dd.read_run(alone), dd.read_run(watched)
    assert a.summary["status"] == b.summary["status"] == "completed"
    assert a.summary["steps_done"] == b.summary["steps_done"] == 500
    assert a.summary["t_final"] == b.summary["t_final"]
    assert sorted(a.summary["final"]) == sorted(b.summary["final"])
    scalars = max(rel(b.summary["final"][k], a.summary["final"][k]) for k in a.summary["final"])
    assert np.array_equal(a.times, b.times) and a.names == b.names and len(a.times) == 101
    fields = max(rel(b.field(name, t).values, a.field(name, t).values)
                 for name in a.names for t in a.times)
    final = max(rel(b.final[key], a.final[key]) for key in a.final)
    assert sorted(a.history) == sorted(b.history)
    history = max(rel(b.history[c], a.history[c]) for c in a.history if c != "step_time_s")
    print(f"with vs without the reader: {len(a.times)} times each; largest relative difference: "
          f"final scalars {scalars:.1e}, fields at every time {fields:.1e}, fields_final.npz "
          f"{final:.1e}, history.csv {history:.1e}")
    assert max(scalars, fields, final, history) < TOL
    damaged = [e for e in stats["errors"] if "holds no" not in e]  # before the first write
    assert not damaged, damaged[:3]  # never a damaged-file error meanwhile
