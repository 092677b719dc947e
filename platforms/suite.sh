#!/usr/bin/env bash
# The test suite of the committed HEAD on another Debian suite's own FEniCSx stack:
#   platforms/suite.sh trixie     (DOLFINx 0.9)
#   platforms/suite.sh sid        (DOLFINx 0.11)
#   platforms/suite.sh --build-only trixie sid   (build/refresh the cached roots only)
# The root (debootstrap minbase + the suite's python3-dolfinx stack) is cached in $ROOTS_DIR
# (default /var/cache/damage-dolfinx/roots, outside the repository) and rebuilt when missing;
# `rm -rf` it to reclaim the ~3 GB. A clean clone is copied in, set up with the same
# `make setup` as on Debian 12 (its venv sees the suite's stack), and `pytest` runs there; the
# suite itself runs every example serially and under mpirun -n 2; it is run with `make test`, as on
# Debian 12. Extra arguments after `--` go to pytest (PYTEST_ARGS). Exit status: pytest's, or 1 with a message when the root cannot be built.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd); repo=$(dirname "$here")
. "$here/lib.sh"
[ "$(id -u)" = 0 ] || { echo "suite: needs root (debootstrap, chroot)" >&2; exit 2; }
command -v debootstrap >/dev/null || { echo "suite: debootstrap missing (apt-get install debootstrap)" >&2; exit 1; }
build_only=0
[ "${1:-}" = --build-only ] && { build_only=1; shift; }
suites=(); while [ $# -gt 0 ] && [ "$1" != -- ]; do suites+=("$1"); shift; done
[ "${1:-}" = -- ] && shift
[ ${#suites[@]} -gt 0 ] || { echo "usage: platforms/suite.sh [--build-only] SUITE... [-- PYTEST ARGS]" >&2; exit 2; }
rc=0
for suite in "${suites[@]}"; do
  root=$(stack_root "$suite") || { echo "suite: FAILED to build the $suite root (see above)" >&2; rc=1; continue; }
  [ $build_only = 1 ] && continue
  copy_clone "$repo" "$root/opt/damage-dolfinx"
  # MPI session directories left in the cached root's /tmp by earlier runs (mpirun killed by a
  # test leaves its own): Open MPI 5/6 names them by mpirun's pid, and a new mpirun that gets a
  # reused pid (pid_max 32768) refuses to start ("prte_session_dir failed: Exists"). Only this
  # suite runs in the root (one leg at a time), so none of them belongs to a live job.
  find "$root/tmp" -mindepth 1 -maxdepth 1 \( -name 'prterun.*' -o -name 'prte.*' -o -name 'ompi.*' \) \
    -exec rm -rf {} +
  t0=$SECONDS
  r=0
  in_root "$root" "cd /opt/damage-dolfinx && make setup >/dev/null && .venv/bin/python -c 'import dolfinx; print(\"$suite: DOLFINx\", dolfinx.__version__)' && make test PYTEST_ARGS='$*'" || r=$?
  echo "suite: $suite exit $r in $((SECONDS - t0)) s"
  [ $r = 0 ] || rc=$r
done
exit $rc
