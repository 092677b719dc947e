"""Helpers shared by the per-step profiles (step_profile_3_3.py, step_floor.py,
damage_fast_path.py): the fastest-of-blocks timing, the loop over the problems and the record
(JSON with the machine load and the checkout that ran, plus a Markdown table)."""
import json
import os
import time
from pathlib import Path


def best(fn, repeat, blocks=5) -> float:
    """Seconds per call of fn, the fastest of ``blocks`` blocks (robust on a loaded machine)."""
    fastest = float("inf")
    for _ in range(blocks):
        start = time.perf_counter()
        for _ in range(repeat):
            fn()
        fastest = min(fastest, (time.perf_counter() - start) / repeat)
    return fastest


def profile_rows(problems, only, profile) -> list:
    """profile(example) for each problem (those in ``only`` if given), each row printed as JSON
    as soon as it is measured."""
    rows = []
    for example in problems:
        if only and example not in only:
            continue
        rows.append(profile(example))
        print(json.dumps(rows[-1]), flush=True)
    return rows


def write_record(out, stem, rows, lines, **extra):
    """``<out>/<stem>.json`` (extra keys, load average, checkout, rows) and ``<stem>.md`` (the
    table ``lines``, also printed)."""
    import damage_dolfinx  # which checkout ran
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{stem}.json").write_text(json.dumps(
        {**extra, "load_average": [round(x, 2) for x in os.getloadavg()],
         "code": str(Path(damage_dolfinx.__file__).parent), "rows": rows}, indent=1))
    (out / f"{stem}.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
