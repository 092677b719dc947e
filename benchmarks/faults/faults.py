"""Fault injection: what a run survives, measured on the real command line.

    python benchmarks/faults/faults.py [--only kill disk ...]
        [--kills 10] [--out results/faults]

Every case starts `damage-dolfinx run` (serially or under mpirun -n 2), injects one fault, records
the exit status, the last stderr line, what was left on disk, then (where the fault is one a run
should survive) frees the fault, resumes with --restart and compares the final fields with an
uninterrupted run of the same command (largest relative l2 difference over all saved fields).

Cases: SIGKILL at --kills random steps of one run per problem (each kill resumed, serially and on
2 ranks) and once during a checkpoint write; disk full (a tmpfs filled at a chosen step: needs
root for `mount`) in the history, the checkpoint and the XDMF file; an I/O error (EIO, injected
into the writes of one file); the output folder deleted;
truncated and zero-length checkpoints; SIGTERM, SIGINT, SIGUSR1 serially and on 2 ranks; a double
run; a restart of a completed run (same and larger T); `run` into a finished folder. Writes
faults.json and faults.md (the table of benchmarks/README.md) to --out.
"""
import argparse
import json
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1", MPLBACKEND="Agg", OMP_NUM_THREADS="1")
#: one small run per problem (a few hundred steps, a few seconds)
PROBLEMS = {"2.1-ex1": ["--n", "10", "--k", "0.005", "--T", "1"],
            "2.2-ex1": ["--n", "8", "--k", "0.005", "--T", "1"],
            "2.3-ex1": ["--n", "8", "--k", "0.005", "--T", "1"],
            "2.4-ex1": ["--n", "8", "--k", "0.005", "--T", "2"],
            "3.1-ex1": ["--n", "8", "--k", "0.005", "--T", "1"],
            "3.2-ex1": ["--n", "8", "--k", "0.005", "--T", "1"],
            "3.3-ex1": ["--n", "8", "--k", "0.01", "--T", "1", "--set", "lam_u=1e6",
                        "--set", "rho=1"]}
BASE = ["--no-figures", "--quiet"]
LOGS = Path(".")
#: the run of the disk, signal and restart cases: 2.4-ex1 (displacement, stress and damage state)
RUN = ["2.4-ex1", "--n", "8", "--k", "0.005", "--T", "2"]
#: a longer run (2000 steps) for the signal and double-run cases
LONG = ["2.4-ex1", "--n", "16", "--k", "0.001", "--T", "2"]


def argv(args, np_=1):
    cmd = [sys.executable, "-m", "damage_dolfinx.cli", "run", *map(str, args)]
    return ["mpirun", "-n", str(np_), *cmd] if np_ > 1 else cmd


def log(out) -> Path:
    """stderr of the runs into ``out`` (outside it: a full disk must not swallow it)."""
    return LOGS / (str(out).strip("/").replace("/", "_") + ".stderr")


def start(args, out, np_=1, extra=()):
    err = open(log(out), "a")
    err.write(f"$ {' '.join(map(str, argv([*args, *extra], np_)))}\n")
    err.flush()
    return subprocess.Popen(argv([*args, *BASE, *extra, "--out", out], np_), env=ENV,
                            stdout=err, stderr=subprocess.STDOUT, start_new_session=True), err


def finish(proc_err, timeout=600):
    proc, err = proc_err
    proc.wait(timeout=timeout)
    err.close()
    text = Path(err.name).read_text()
    lines = [l for l in text[text.rfind("\n$ ") + 1:].splitlines()[1:] if l.strip()]
    # mpirun adds its own banner after a rank's non-zero exit: keep our line
    ours = [l for l in lines if l.startswith("damage-dolfinx:")]
    tb = any("Traceback" in l for l in lines)
    errors = [l for l in lines if re.match(r"^[\w.]+(Error|Exception): ", l)]
    return proc.returncode, (ours[-1] if ours else errors[-1] if errors and tb else
                             lines[-1] if lines else ""), tb


def run(args, out, np_=1, extra=()):
    return finish(start(args, out, np_, extra))


def last_step(out) -> int:
    try:
        with open(Path(out) / "history.csv", "rb") as f:
            f.seek(max(0, os.path.getsize(f.name) - 600))
            lines = f.read().decode(errors="replace").split("\n")[:-1]
        return int(lines[-1].split(",")[0]) if lines and lines[-1][:1].isdigit() else -1
    except (OSError, ValueError, IndexError):
        return -1


def wait_step(proc, out, step, timeout=300):
    """Poll until the history has a row of ``step`` (or the process ends); returns the step."""
    deadline = time.time() + timeout
    while time.time() < deadline and proc.poll() is None:
        s = last_step(out)
        if s >= step:
            return s
        time.sleep(0.002)
    return last_step(out)


def kill(proc, sig=signal.SIGKILL, ranks_only=False, mpirun_only=False):
    """Signal the whole session (mpirun and its ranks), only the ranks (what srun does), or
    only mpirun (a user's `kill`)."""
    pids = subprocess.run(["pgrep", "-s", str(proc.pid)], capture_output=True,
                          text=True).stdout.split() if not mpirun_only else [str(proc.pid)]
    for pid in pids:
        if ranks_only and int(pid) == proc.pid and len(pids) > 1:
            continue
        try:
            os.kill(int(pid), sig)
        except ProcessLookupError:
            pass


def reference(out, args, np_=1) -> Path:
    """The uninterrupted run of ``args`` on ``np_`` ranks (run once per benchmark)."""
    ref = Path(out) / ("ref_" + "_".join(a.lstrip("-").replace("=", "") for a in args)
                       + f"_np{np_}")
    if not (ref / "fields_final.npz").exists():
        code, msg, tb = run(args, ref, np_)
        assert code == 0, msg
    return ref


def fields_diff(out, ref) -> float:
    a, b = np.load(Path(out) / "fields_final.npz"), np.load(Path(ref) / "fields_final.npz")
    return max(float(np.linalg.norm(a[k] - b[k]) / max(np.linalg.norm(b[k]), 1e-300))
               for k in b.files if not k.endswith("_coords"))


def kept(out) -> str:
    """What the folder holds: history rows, checkpoint generations, summary status."""
    out = Path(out)
    parts = []
    if (out / "history.csv").exists():
        parts.append(f"history to step {last_step(out)}")
    for name in ("checkpoint.npz", "checkpoint.prev.npz"):
        try:
            with np.load(out / name) as d:
                parts.append(f"{name} step {json.loads(str(d['__meta__']))['step']}")
        except Exception:  # noqa: BLE001
            if (out / name).exists():
                parts.append(f"{name} unreadable")
    try:
        s = json.loads((out / "summary.json").read_text())
        parts.append(f"summary {s['status']}" + (f" ({s['steps_done']} steps)"
                                                 if s["status"] != "completed" else ""))
    except (OSError, ValueError):
        parts.append("no summary")
    if (out / "fields.xdmf").exists():
        import xml.etree.ElementTree as ET
        try:
            n = len({e.get("Value") for e in ET.parse(out / "fields.xdmf").getroot().iter("Time")})
            parts.append(f"fields.xdmf parses ({n} output times)")
        except ET.ParseError:
            parts.append("fields.xdmf does not parse")
    return "; ".join(parts)


class Table:
    def __init__(self):
        self.rows = []

    def add(self, case, fault, status, message, kept_, diff=None, expect=None, tb=False,
            fail=False):
        """One row; it passes with the expected exit status, no traceback, no other failure
        (``fail``: a resume that did not finish, a message naming the wrong file, ...) and a
        resumed run within 1e-12 (relative) of the uninterrupted one."""
        ok = (expect is None or status in expect) and not tb and not fail and \
            (diff is None or diff < 1e-12)
        row = {"case": case, "fault": fault, "exit_status": status, "message": message,
               "kept": kept_, "resumed_vs_reference": diff, "traceback": tb, "pass": ok}
        self.rows.append(row)
        print(json.dumps(row), flush=True)
        return row


def case_kills(t, out, problem, np_, kills, rng):
    """SIGKILL a run at `kills` random steps, resume each time; compare with the uninterrupted."""
    args = [problem.split()[0], *PROBLEMS[problem]]
    ref, part = reference(out, args, np_), out / f"kill_{problem.replace(' ', '_')}_np{np_}"
    N = json.loads((ref / "summary.json").read_text())["num_steps"]
    steps = sorted(rng.sample(range(2, N - 1), kills))
    killed, statuses = [], set()
    for i, step in enumerate(steps):
        # a run killed before its first checkpoint starts again (--overwrite)
        again = ["--restart"] if (part / "checkpoint.npz").exists() or \
            (part / "checkpoint.prev.npz").exists() else ["--overwrite"]
        p = start(args, part, np_, ["--checkpoint-every", "3", *again])
        at = wait_step(p[0], part, step)
        if p[0].poll() is None:
            kill(p[0])
            killed.append(at)
        code, msg, tb = finish(p)
        statuses.add(code)
        if tb:
            break
    code, msg, tb2 = run(args, part, np_, ["--checkpoint-every", "3", "--restart"])
    t.add(f"kill-{problem}-np{np_}", f"{problem}: SIGKILL at steps {killed} of {N} ({np_} "
          "rank(s)), each resumed with --restart", sorted(statuses), "(killed: no message)", kept(part),
          fields_diff(part, ref) if code == 0 else None, expect=None, tb=tb or tb2,
          fail=code != 0)


def case_kill_in_checkpoint(t, out):
    """SIGKILL while checkpoint.npz.tmp is being written (a larger mesh: the write lasts
    milliseconds); retried at later checkpoints until the kill lands inside a write."""
    args = ["2.4-ex1", "--n", "128", "--k", "0.005", "--T", "0.25"]
    ref, part = reference(out, args), out / "kill_ckpt"
    tmp, left, hit, codes, tb = part / "checkpoint.npz.tmp", False, None, set(), False
    for attempt in range(20):
        again = ["--restart"] if (part / "summary.json").exists() else []
        p = start(args, part, 1, ["--checkpoint-every", "2", *again])
        while p[0].poll() is None:
            if tmp.exists() and (part / "checkpoint.npz").exists():
                os.kill(p[0].pid, signal.SIGKILL)  # at once (no pgrep): the window is short
                break
        code, msg, tb1 = finish(p)
        codes.add(code)
        tb = tb or tb1
        left, hit = tmp.exists(), last_step(part)
        if code == 0:  # the run ended before a kill landed inside a write: start it again
            shutil.rmtree(part)
            continue
        if left:
            break
    what = kept(part) + (f"; checkpoint.npz.tmp left ({tmp.stat().st_size} bytes)"
                         if left else "")
    code2, msg2, tb2 = run(args, part, 1, ["--checkpoint-every", "2", "--restart"])
    t.add("kill-during-checkpoint", f"SIGKILL during a checkpoint write (after step {hit}, "
          f"attempt {attempt + 1}), then --restart", sorted(codes), "(killed: no message)",
          what, fields_diff(part, ref) if code2 == 0 else None,
          tb=tb or tb2, fail=code2 != 0 or not left)


def fill(mount, leave: int):
    """Fill the tmpfs at ``mount`` until ``leave`` bytes stay free."""
    filler = Path(mount) / "filler"
    free = shutil.disk_usage(mount).free
    with open(filler, "ab") as f:
        try:
            f.write(b"\0" * max(0, free - leave))
            f.flush()
        except OSError:
            pass
    return filler


def case_disk_full(t, out, mount, name, leave, at_step, extra, expect_file):
    """Fill the disk at ``at_step``; the run must stop with exit 4 naming ``expect_file``; then
    free the space and resume."""
    ref = reference(out, RUN)
    folder = Path(mount) / name
    p = start(RUN, folder, 1, extra)
    wait_step(p[0], folder, at_step)
    filler = fill(mount, leave)
    code, msg, tb = finish(p)
    what = kept(folder)
    filler.unlink()
    code2, msg2, tb2 = run(RUN, folder, 1, [*extra, "--restart"])
    diff = fields_diff(folder, ref) if code2 == 0 else None
    t.add(f"disk-full-{name}", f"disk full after step {at_step} ({leave // 1024} kB left), "
          "then space freed and --restart", code, msg, what, diff, expect={4},
          tb=tb or tb2, fail=expect_file not in msg or code2 != 0)
    shutil.rmtree(folder)


def case_signal(t, out, sig, np_, ranks_only, extra=(), env_extra=None, expect=None):
    folder = out / f"signal_{sig.name}_np{np_}{'_ranks' if ranks_only else ''}"
    args = LONG
    ref = reference(out, args, np_)
    env = dict(ENV, **(env_extra or {}))
    err = open(log(folder), "a")
    err.write(f"$ {' '.join(map(str, argv([*args, *extra], np_)))}\n")
    err.flush()
    proc = subprocess.Popen(argv([*args, *BASE, *extra, "--out", folder], np_), env=env,
                            stdout=err, stderr=subprocess.STDOUT, start_new_session=True)
    at = wait_step(proc, folder, 300)
    kill(proc, sig, ranks_only=ranks_only, mpirun_only=np_ > 1 and not ranks_only)
    code, msg, tb = finish((proc, err))
    what = kept(folder)
    code2, msg2, tb2 = run(args, folder, np_, [*extra, "--restart"])
    target = "the ranks" if ranks_only else ("mpirun" if np_ > 1 else "the process")
    t.add(f"{sig.name}-np{np_}{'-ranks' if ranks_only else ''}",
          f"{sig.name} to {target} after step {at}" + (f" ({env_extra})" if env_extra else ""),
          code, msg, what, fields_diff(folder, ref) if code2 == 0 else None,
          expect=expect or {128 + sig}, tb=tb or tb2, fail=code2 != 0)


def case_checkpoint_files(t, out):
    """A truncated and a zero-length newest checkpoint: the restart falls back to the previous."""
    ref = reference(out, RUN)
    for how in ("truncated", "zero-length"):
        folder = out / f"checkpoint_{how}"
        p = start(RUN, folder, 1, ["--checkpoint-every", "50"])
        wait_step(p[0], folder, 230)
        kill(p[0])
        finish(p)
        path = folder / "checkpoint.npz"
        size = path.stat().st_size
        with open(path, "r+b") as f:
            f.truncate(size // 2 if how == "truncated" else 0)
        what = kept(folder)
        code, msg, tb = run(RUN, folder, 1, ["--checkpoint-every", "50", "--restart"])
        fallback = log(folder).read_text().splitlines()
        note = next((l for l in fallback if "unreadable" in l), msg)
        t.add(f"checkpoint-{how}", f"checkpoint.npz {how} ({size} -> "
              f"{size // 2 if how == 'truncated' else 0} bytes), then --restart", code, note,
              what, fields_diff(folder, ref) if code == 0 else None, expect={0}, tb=tb)


#: the command line with the writes of files named ARGV[1]* failing with EIO from the ARGV[2]-th
#: on (a failing disk; the same injection as tests/test_faults.py)
EIO = """import builtins, errno, os, sys
from damage_dolfinx.runtime import atomic, io
name, after, count = sys.argv[1], int(sys.argv[2]), [0]
class Failing:
    def __init__(self, f): self._f = f
    def write(self, data):
        count[0] += 1
        if count[0] >= after: raise OSError(errno.EIO, os.strerror(errno.EIO))
        return self._f.write(data)
    def __getattr__(self, attr): return getattr(self._f, attr)
    def __enter__(self): return self
    def __exit__(self, *exc): self._f.close()
def fake_open(path, mode="r", *args, **kwargs):
    f = builtins.open(path, mode, *args, **kwargs)
    return Failing(f) if os.path.basename(path).startswith(name) else f
atomic.open = io.open = fake_open
from damage_dolfinx.cli import main
sys.exit(main(sys.argv[3:]))
"""


def case_eio(t, out, name, after, extra):
    """EIO in the writes of ``name`` (injected); then --restart without the fault."""
    ref, folder = reference(out, RUN), out / f"eio_{name}"
    err = open(log(folder), "a")
    cmd = [sys.executable, "-c", EIO, name, str(after), "run", *RUN, *BASE, *extra,
           "--out", str(folder)]
    err.write(f"$ python -c EIO {name} {after} run {' '.join(RUN + extra)}\n")
    err.flush()
    code, msg, tb = finish((subprocess.Popen(cmd, env=ENV, stdout=err,
                                             stderr=subprocess.STDOUT), err))
    what = kept(folder)
    code2, msg2, tb2 = run(RUN, folder, 1, [*extra, "--restart"])
    t.add(f"eio-{name}", f"EIO writing {name} (injected, write {after} on), then --restart",
          code, msg, what, fields_diff(folder, ref) if code2 == 0 else None, expect={4},
          tb=tb or tb2, fail=f"cannot write {name}" not in msg or code2 != 0)


def case_folder_deleted(t, out):
    folder = out / "deleted"
    p = start(RUN, folder, 1, ["--write-every", "10"])
    wait_step(p[0], folder, 100)
    shutil.rmtree(folder)
    code, msg, tb = finish(p)
    t.add("folder-deleted", "output folder deleted after step 100", code, msg,
          "nothing (the folder is gone)", None, expect={4}, tb=tb)


def case_double_and_restart(t, out):
    ref, args = reference(out, RUN), LONG
    folder = out / "double"
    first = start(args, folder, 1, ["--checkpoint-every", "100"])
    wait_step(first[0], folder, 150)
    code, msg, tb = run(args, folder, 1, ["--overwrite"])
    t.add("double-run", "a second run (--overwrite) into the folder of a live run", code, msg,
          kept(folder), None, expect={2}, tb=tb)
    kill(first[0])
    finish(first)
    code, msg, tb = run(args, folder, 1, ["--checkpoint-every", "100", "--restart"])
    t.add("dead-run-lock", "--restart after the live run was SIGKILLed (its .lock left on disk)",
          code, msg or "(completed)", kept(folder), fields_diff(folder, reference(out, args)),
          expect={0}, tb=tb)
    done = out / "completed"
    run(RUN, done)
    before = {f: (done / f).read_bytes() for f in ("summary.json", "history.csv",
                                                   "fields_final.npz")}
    code, msg, tb = run(RUN, done, 1, ["--restart"])
    same = all((done / f).read_bytes() == b for f, b in before.items())
    t.add("restart-completed", "--restart of a completed run (same T)", code, msg,
          f"summary, history, final fields byte-identical: {same}", None, expect={0},
          tb=tb, fail=not same)
    code, msg, tb = run(RUN, done, 1, [])
    t.add("run-into-finished", "`run` without --restart into the completed folder", code, msg,
          f"unchanged: {all((done / f).read_bytes() == b for f, b in before.items())}", None,
          expect={2}, tb=tb)
    longer = [*RUN[:-1], "3"]
    code, msg, tb = run(longer, done, 1, ["--restart"])
    s = json.loads((done / "summary.json").read_text())
    t.add("restart-completed-larger-T", "--restart of the completed run with T 2 -> 3", code,
          msg or f"(continued from step {s['restarts'][0]['step']})", kept(done),
          fields_diff(done, reference(out, longer)), expect={0}, tb=tb)
    code, msg, tb = run(RUN, done, 1, ["--overwrite"])
    t.add("overwrite", "`run --overwrite` into the completed folder", code, msg or "(completed)",
          kept(done), fields_diff(done, ref), expect={0}, tb=tb)


def case_issue(t, out):
    """The three faults of the issue's table, as a new user met them (run with --pythonpath
    pointing at an older checkout to measure 'before')."""
    done = out / "issue_completed"
    run(RUN, done, 1, ["--checkpoint-every", "50"])
    code, msg, tb = run(RUN, done, 1, ["--checkpoint-every", "50", "--restart"])
    s = json.loads((done / "summary.json").read_text())
    t.add("issue-restart-completed", "`--restart` into the folder of a completed run", code, msg,
          f"summary {s['status']}, steps_done {s['steps_done']}, final block: {'final' in s}",
          None, expect={0}, tb=tb, fail=s["steps_done"] != s["num_steps"] or "final" not in s)
    mount = out / "tmpfs300k"
    mount.mkdir()
    subprocess.run(["mount", "-t", "tmpfs", "-o", "size=300k", "tmpfs", str(mount)], check=True)
    try:
        code, msg, tb = run(RUN, mount / "run")
        t.add("issue-disk-full", "the output disk fills up (a 300 kB tmpfs as --out)", code, msg,
              kept(mount / "run"), None, expect={4}, tb=tb)
    finally:
        _umount(mount)
    folder = out / "issue_truncated"
    p = start(RUN, folder, 1, ["--checkpoint-every", "50"])
    wait_step(p[0], folder, 230)
    kill(p[0])
    finish(p)
    path = folder / "checkpoint.npz"
    with open(path, "r+b") as f:
        f.truncate(path.stat().st_size // 2)
    what = kept(folder)
    code, msg, tb = run(RUN, folder, 1, ["--checkpoint-every", "50", "--restart"])
    lines = log(folder).read_text().splitlines()
    msg = next((l for l in lines if "unreadable" in l), msg)
    t.add("issue-truncated-checkpoint", "checkpoint.npz truncated (half its bytes), --restart",
          code, msg, what, fields_diff(folder, reference(out, RUN)) if code == 0 else None,
          expect={0}, tb=tb)


def _umount(mount):
    for _ in range(10):
        if subprocess.run(["umount", str(mount)], capture_output=True).returncode == 0:
            return
        time.sleep(0.5)


def write_tables(rows, out, header=""):
    lines = [header, ""] if header else []
    lines += ["| fault | exit status | message (stderr, one line) | kept | resumed vs reference "
             "| pass |", "|---|---|---|---|---|---|"]
    for r in rows:
        d = r["resumed_vs_reference"]
        lines.append(f"| {r['fault']} | {r['exit_status']} | {r['message'].replace('|', '/')} | "
                     f"{r['kept']} | {'-' if d is None else f'{d:.1e}'} | "
                     f"{'yes' if r['pass'] else 'NO'} |")
    (out / "faults.md").write_text("\n".join(lines) + "\n")
    (out / "faults.json").write_text(json.dumps({"header": header, "rows": rows}, indent=1) + "\n")
    print("\n".join(lines))


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--out", default="results/faults")
    p.add_argument("--kills", type=int, default=10)
    p.add_argument("--seed", type=int, default=20)
    p.add_argument("--only", nargs="+", choices=("issue", "kill", "kill-checkpoint", "disk",
                                                  "checkpoint", "eio", "signal", "double",
                                                  "deleted"))
    p.add_argument("--problems", nargs="*", default=list(PROBLEMS))
    p.add_argument("--pythonpath", help="run the command line of another checkout (before/after)")
    a = p.parse_args()
    if a.pythonpath:
        ENV["PYTHONPATH"] = a.pythonpath
    out = Path(a.out).resolve()
    if out.exists():
        shutil.rmtree(out)
    out.mkdir(parents=True)
    global LOGS
    LOGS = out / "logs"
    LOGS.mkdir()
    t, rng, only = Table(), random.Random(a.seed), set(a.only or ())
    start_time = time.time()
    if not only or "issue" in only:
        case_issue(t, out)
    if not only or "disk" in only:
        mount = out / "tmpfs"
        mount.mkdir()
        subprocess.run(["mount", "-t", "tmpfs", "-o", "size=2m", "tmpfs", str(mount)], check=True)
        try:
            case_disk_full(t, out, mount, "history", 0, 101, ["--checkpoint-every", "50",
                                                             "--write-every", "400"], "history.csv")
            case_disk_full(t, out, mount, "checkpoint", 12 << 10, 101,
                           ["--checkpoint-every", "50", "--write-every", "400"], "checkpoint.npz")
            case_disk_full(t, out, mount, "xdmf", 12 << 10, 101,
                           ["--checkpoint-every", "50", "--write-every", "10"], "fields.xdmf")
        finally:
            _umount(mount)
    if not only or "checkpoint" in only:
        case_checkpoint_files(t, out)
    if not only or "eio" in only:
        for name, after in (("history.csv", 120), ("checkpoint.npz", 3), ("summary.json", 12)):
            case_eio(t, out, name, after, ["--checkpoint-every", "50"])
    if not only or "deleted" in only:
        case_folder_deleted(t, out)
    if not only or "signal" in only:
        for sig in (signal.SIGTERM, signal.SIGINT):
            case_signal(t, out, sig, 1, False)
        case_signal(t, out, signal.SIGTERM, 2, True)
        case_signal(t, out, signal.SIGUSR1, 2, False)
        case_signal(t, out, signal.SIGTERM, 2, False, expect={1})
    if not only or "double" in only:
        case_double_and_restart(t, out)
    if not only or "kill" in only or "kill-checkpoint" in only:
        case_kill_in_checkpoint(t, out)
    if not only or "kill" in only:
        for problem in a.problems:
            for np_ in (1, 2):
                case_kills(t, out, problem, np_, a.kills, rng)
    repo = Path(__file__).resolve().parents[2]
    commit = subprocess.run(["git", "-C", str(repo), "rev-parse", "--short", "HEAD"],
                            capture_output=True, text=True).stdout.strip()
    code = ENV.get("PYTHONPATH") or f"{repo} at {commit}"
    header = (f"`python benchmarks/faults/faults.py {' '.join(sys.argv[1:])}`: code {code}, "
              f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, wall time "
              f"{time.time() - start_time:.0f} s; {sum(r['pass'] for r in t.rows)}/{len(t.rows)} "
              "rows pass")
    write_tables(t.rows, out, header)


if __name__ == "__main__":
    main()
