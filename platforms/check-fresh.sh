#!/usr/bin/env bash
# make check-fresh: the README's two commands on a bare Debian 12 machine, proven.
#
# Builds a debootstrap --variant=minbase bookworm root (nothing of the stack in it), copies a clean
# clone of the committed HEAD into it, and runs exactly `make demo` then `make test` there, each
# timed, installation included. The only thing put in before is `make` itself (minbase has no
# make, and the README's commands are make commands). AS_USER=1 runs them as a non-root user
# with sudo instead of as root. Writes a JSON record to $OUT (default results/check-fresh.json).
# Needs root (debootstrap, chroot, mounts) and network access to the machine's Debian mirror.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd); repo=$(dirname "$here")
. "$here/lib.sh"
[ "$(id -u)" = 0 ] || { echo "check-fresh: needs root (debootstrap, chroot)" >&2; exit 2; }
command -v debootstrap >/dev/null || { echo "check-fresh: debootstrap missing (apt-get install debootstrap)" >&2; exit 2; }
SUITE=${SUITE:-bookworm}
AS_USER=${AS_USER:-0}
OUT=${OUT:-$repo/results/check-fresh$([ "$AS_USER" = 1 ] && echo -user || true).json}
root="$ROOTS_DIR/fresh-$SUITE"
mkdir -p "$(dirname "$OUT")"
t0=$SECONDS
bare_root "$SUITE" "$root"
t_boot=$((SECONDS - t0))
copy_clone "$repo" "$root/opt/damage-dolfinx"
if [ "$AS_USER" = 1 ]; then
  prep="apt-get update -q >/dev/null && DEBIAN_FRONTEND=noninteractive apt-get install -y -q make sudo >/dev/null &&
        useradd -m researcher && echo 'researcher ALL=(ALL) NOPASSWD:ALL' > /etc/sudoers.d/researcher &&
        chown -R researcher /opt/damage-dolfinx"
  run() { echo "cd /opt/damage-dolfinx && su researcher -c '$1'"; }
else
  prep="apt-get update -q >/dev/null && DEBIAN_FRONTEND=noninteractive apt-get install -y -q make >/dev/null"
  run() { echo "cd /opt/damage-dolfinx && $1"; }
fi
in_root "$root" "$prep"
result=()
for cmd in "make demo" "make test"; do
  log="$root.$(echo "$cmd" | tr ' ' -).log"
  s=$SECONDS; rc=0
  in_root "$root" "$(run "$cmd")" >"$log" 2>&1 || rc=$?
  dt=$((SECONDS - s)); load=$(cut -d' ' -f1-3 /proc/loadavg)
  echo "check-fresh: '$cmd' in a fresh $SUITE minbase root$([ "$AS_USER" = 1 ] && echo ' as a non-root sudoer' || true): exit $rc, ${dt} s (log $log)"
  tail -3 "$log" | sed 's/^/    /'
  result+=("{\"command\": \"$cmd\", \"exit\": $rc, \"wall_time_s\": $dt, \"loadavg_after\": \"$load\", \"last_line\": $( (grep -E "passed|failed|demo output" "$log" || tail -1 "$log") | tail -1 | python3 -c 'import json,sys; print(json.dumps(sys.stdin.read().strip()))')}")
done
commit=$(git -C "$repo" rev-parse --short HEAD)
( IFS=,; echo "{\"suite\": \"$SUITE\", \"as_user\": $AS_USER, \"commit\": \"$commit\", \"debootstrap_s\": $t_boot, \"commands\": [${result[*]}]}" ) \
  | python3 -m json.tool > "$OUT"
echo "check-fresh: record in $OUT"
[ "${KEEP_ROOT:-0}" = 1 ] || remove_root "$root"
grep -q '"exit": [1-9]' "$OUT" && exit 1 || exit 0
