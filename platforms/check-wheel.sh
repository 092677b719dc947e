#!/usr/bin/env bash
# The package as a user installs it: the wheel built from this checkout (pip wheel --no-deps
# --no-build-isolation), installed into a fresh `python3 -m venv --system-site-packages` venv
# (the FEniCSx stack of the machine, nothing of the checkout), then used from an empty folder
# outside the checkout: the command line (--version, -h, list, show, a short run), the README's
# own-problem example, one demo, and a model of one's own loaded from a plugin file, run by id.
#   platforms/check-wheel.sh [PYTHON]      (default /usr/bin/python3; tests/test_wheel.py runs it)
# Prints every command with what it printed; exit status 0 when all of them succeed.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
py=${1:-/usr/bin/python3}
work=$(mktemp -d "${TMPDIR:-/tmp}/damage-dolfinx-wheel.XXXXXX")
trap 'rm -rf "$work"' EXIT
# nothing of the checkout or of a test harness reaches the user's processes
unset PYTHONPATH DAMAGE_DOLFINX_PLUGINS MPLBACKEND PYTHONSTARTUP
export PIP_DISABLE_PIP_VERSION_CHECK=1 PIP_NO_INDEX=1

say() { printf '$ %s\n' "$*"; }
step() {  # step CMD...: print the command, run it, print its output (head), fail on status
  say "$@"
  local out rc=0
  out=$("$@" 2>&1) || rc=$?
  printf '%s\n' "$out" | head -n "${LINES_SHOWN:-12}"
  [ $rc = 0 ] || { echo "check-wheel: FAILED ($rc): $*" >&2; printf '%s\n' "$out" | tail -n 30 >&2; exit 1; }
}

# a copy of the sources (a build in the checkout would reuse its build/ folder)
mkdir -p "$work/src"
tar -C "$repo" --exclude=./.venv --exclude=./.git --exclude=./build --exclude=./results \
    --exclude='*.egg-info' --exclude=__pycache__ -cf - . | tar -C "$work/src" -xf -
step "$py" -m venv --system-site-packages "$work/venv"
cd "$work/src"
step "$work/venv/bin/python" -m pip wheel --no-deps --no-build-isolation -q -w "$work/dist" .
wheel=$(ls "$work/dist"/damage_dolfinx-*.whl)
step "$work/venv/bin/python" -m pip install --no-deps -q "$wheel"
rm -rf "$work/src"/build

# every module of the sources is in the wheel (the package folders are found, not listed)
step "$work/venv/bin/python" - "$wheel" "$repo" <<'PY'
import sys, zipfile, pathlib
wheel, repo = sys.argv[1], pathlib.Path(sys.argv[2])
names = set(zipfile.ZipFile(wheel).namelist())
want = {str(p.relative_to(repo)) for p in (repo / "damage_dolfinx").rglob("*.py")}
for folder in ("forms", "geometries"):
    want |= {"damage_dolfinx/" + str(p.relative_to(repo)) for p in (repo / folder).rglob("*.py")}
want |= {"damage_dolfinx/py.typed"}
missing = sorted(want - names)
assert not missing, f"not in the wheel: {missing}"
assert any(n.endswith(".dist-info/LICENSE") or "/licenses/LICENSE" in n for n in names), "no LICENSE"
print(f"wheel: {len(want)} files of the sources, all present; LICENSE, py.typed")
PY

# the user's empty folder, outside the checkout
mkdir "$work/user"; cd "$work/user"
export PATH="$work/venv/bin:$PATH"
step "$work/venv/bin/python" -c "import damage_dolfinx, sys; \
assert damage_dolfinx.__file__.startswith('$work/venv'), damage_dolfinx.__file__; print(damage_dolfinx.__file__)"
step damage-dolfinx --version
LINES_SHOWN=6 step damage-dolfinx -h
LINES_SHOWN=4 step damage-dolfinx list
LINES_SHOWN=20 step damage-dolfinx show 2.1-ex1
step damage-dolfinx run 2.1-ex1 --n 5 --T 0.05 --no-figures --quiet --out run-ex1
test -f run-ex1/summary.json

# the README's own-problem example, as the README writes it (T shortened)
"$work/venv/bin/python" - "$repo/README.md" > own_problem.py <<'PY'
import re, sys
text = open(sys.argv[1]).read()
section = text.split("## Your own problem", 1)[1]
code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
print(code.replace("T=0.5", "T=0.05"))
PY
step "$work/venv/bin/python" own_problem.py
test -f results/rectangle/summary.json

# one demo (the user's own matplotlib plot included)
cp "$repo/demos/demo_own_damage_law.py" .
DAMAGE_DOLFINX_DEMO_OUT=demo step "$work/venv/bin/python" demo_own_damage_law.py

# an own model from a plugin file, run by its id from the command line
cat > my_model.py <<'PY'
"""A model of one's own: model 2.1 under another id, with a mesh of its own (example())."""
import damage_dolfinx as dd
from damage_dolfinx.geometries.rectangle import rectangle, side


@dd.register_model
class MyElastic(dd.model_class("2.1")):
    id = "my-elastic"
    title = "model 2.1 on a bar, from a plugin file"

    @classmethod
    def example(cls):
        def bar(comm, n):
            return rectangle(comm, (0, 0), (1, 0.25), 4 * n, n, {1: side(0, 0.0), 2: side(0, 1.0)})
        import ufl
        return dd.Problem(model=cls, mesh=bar, n=2, T=0.1, k=0.05, name=cls.id,
                          boundaries={"clamped": 1, "traction": 2},
                          traction=lambda x, t: ufl.as_vector((t, 0.0)))
PY
step damage-dolfinx run my-elastic --plugin ./my_model.py --no-figures --quiet --out run-mine
test -f run-mine/summary.json
# the same plugin as a module of the current folder (a console script does not see it)
DAMAGE_DOLFINX_PLUGINS=my_model LINES_SHOWN=8 step damage-dolfinx show my-elastic
echo "check-wheel: all passed ($(damage-dolfinx --version))"
