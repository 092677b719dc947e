#!/usr/bin/env bash
# The same small run per problem on DOLFINx 0.5.2 (this Debian 12 machine), 0.9 (trixie root) and
# 0.11 (sid root), all from one clean clone of the committed HEAD, then the comparison table:
#   platforms/cross-version.sh [OUT.md]     (default results/cross_version.md)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd); repo=$(dirname "$here")
. "$here/lib.sh"
[ "$(id -u)" = 0 ] || { echo "cross-version: needs root (debootstrap, chroot)" >&2; exit 2; }
md=${1:-$repo/results/cross_version.md}
mkdir -p "$(dirname "$md")"
work=$(mktemp -d -t cross-version.XXXXXX)
copy_clone "$repo" "$work/clone"  # one snapshot of HEAD for all three versions
git -C "$repo" rev-parse --short HEAD > "$work/commit"
(cd "$work/clone" && make -s setup >/dev/null && .venv/bin/python benchmarks/platforms/cross_version.py run --out "$work/bookworm")
folders=("$work/bookworm")
for suite in trixie sid; do
  root=$(stack_root "$suite")
  rm -rf "$root/opt/damage-dolfinx"; cp -a "$work/clone" "$root/opt/damage-dolfinx"
  rm -rf "$root/opt/damage-dolfinx/.venv"  # the same sources as the host run, the root's own venv
  in_root "$root" "cd /opt/damage-dolfinx && make -s setup >/dev/null && .venv/bin/python benchmarks/platforms/cross_version.py run --out /opt/cross-version"
  rm -rf "$work/$suite"; cp -r "$root/opt/cross-version" "$work/$suite"
  folders+=("$work/$suite")
done
"$work/clone/.venv/bin/python" "$work/clone/benchmarks/platforms/cross_version.py" compare "${folders[@]}" --md "$md"
sed -i "1s/^/Commit $(cat "$work/commit"), one clean clone for all three versions. /" "$md"
echo "cross-version: table in $md (runs in $work)"
