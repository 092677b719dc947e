#!/usr/bin/env bash
# Shared pieces of the platform checks: the package mirror (read from this machine's own apt
# sources, never written into the repository), debootstrap roots cached outside the repository,
# and running a command inside a root with /proc, /sys and /dev mounted (OpenMPI needs /proc,
# UCX warns without /sys, Chromium needs /dev/shm).
set -euo pipefail

ROOTS_DIR=${ROOTS_DIR:-/var/cache/damage-dolfinx/roots}

# The Debian stack of each suite (python3-dolfinx-real exists from trixie on; bookworm's
# python3-dolfinx is the real build).
stack_packages() {
  local dolfinx=python3-dolfinx-real
  [ "$1" = bookworm ] && dolfinx=python3-dolfinx
  echo "$dolfinx python3-petsc4py python3-mpi4py python3-ufl python3-basix python3-ffcx python3-meshio" \
       "python3-gmsh openmpi-bin python3-pytest python3-matplotlib python3-scipy python3-venv" \
       "python3-setuptools python3-pip gcc make chromium"
}

# First Debian archive URI in the machine's apt sources (deb822 .sources or one-line .list).
mirror() {
  local uri
  uri=$( { cat /etc/apt/sources.list.d/*.sources 2>/dev/null || true; } |
         awk '/^URIs:/ {print $2}' | grep -v -- '-security' | head -n1)
  if [ -z "$uri" ]; then
    uri=$( { cat /etc/apt/sources.list /etc/apt/sources.list.d/*.list 2>/dev/null || true; } |
           awk '$1 == "deb" {for (i = 2; i <= NF; i++) if ($i ~ /^[a-z]+:\/\//) {print $i; exit}}' |
           grep -v -- '-security' | head -n1)
  fi
  [ -n "$uri" ] || { echo "platforms: no Debian mirror found in /etc/apt/sources*" >&2; return 1; }
  echo "$uri"
}

# bare_root SUITE DIR: a debootstrap --variant=minbase root (nothing else installed).
bare_root() {
  local suite=$1 dir=$2 m
  m=$(mirror)
  remove_root "$dir"
  mkdir -p "$(dirname "$dir")"
  echo "platforms: debootstrap --variant=minbase $suite (mirror from /etc/apt) -> $dir" >&2
  debootstrap --variant=minbase "$suite" "$dir" "$m" >"$dir.debootstrap.log" 2>&1 ||
    { echo "platforms: debootstrap $suite failed, see $dir.debootstrap.log" >&2; tail -5 "$dir.debootstrap.log" >&2; return 1; }
  # the machine's own apt settings (a snapshot mirror needs e.g. Acquire::Check-Valid-Until)
  cp -n /etc/apt/apt.conf.d/* "$dir/etc/apt/apt.conf.d/" 2>/dev/null || true
  # unstable's minbase has no apt sources for its own suite name under some debootstrap versions
  [ -s "$dir/etc/apt/sources.list" ] || echo "deb $m $suite main" > "$dir/etc/apt/sources.list"
}

# in_root DIR CMD...: run CMD (through bash -lc) inside DIR with /proc, /sys, /dev mounted.
in_root() {
  local dir=$1; shift
  cp -L /etc/resolv.conf "$dir/etc/resolv.conf" 2>/dev/null || true
  mount -t proc proc "$dir/proc"
  mount --rbind /sys "$dir/sys"; mount --make-rslave "$dir/sys"
  mount --rbind /dev "$dir/dev"; mount --make-rslave "$dir/dev"
  local rc=0
  chroot "$dir" /usr/bin/env -i HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
      LANG=C.UTF-8 TERM=dumb /bin/bash -c "$*" || rc=$?
  unmount_all "$dir"
  return $rc
}

# unmount_all DIR: every mount below DIR, deepest first (lazily when busy, e.g. a process still
# holding /dev/shm).
unmount_all() {
  local m
  for m in $(findmnt -rn -o TARGET | grep "^$1/" | sort -r); do
    umount "$m" 2>/dev/null || umount -l "$m" 2>/dev/null || true
  done
}

# remove_root DIR: rm -rf a root, but never while anything (the host's /dev, /sys!) is mounted in it.
remove_root() {
  unmount_all "$1"
  if findmnt -rn -o TARGET | grep -q "^$1/"; then
    echo "platforms: NOT removing $1: still mounted: $(findmnt -rn -o TARGET | grep "^$1/" | tr '\n' ' ')" >&2
    return 1
  fi
  rm -rf "$1"
}

# stack_root SUITE: a cached root of SUITE with the suite's own FEniCSx stack; rebuilt when
# missing or when the package list changed. Prints its path.
stack_root() {
  local suite=$1 dir="$ROOTS_DIR/$1" pkgs stamp
  pkgs=$(stack_packages "$suite")
  stamp="$dir/.damage-dolfinx-stack"
  if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$pkgs" ]; then echo "$dir"; return 0; fi
  local t0=$SECONDS
  bare_root "$suite" "$dir" >&2
  in_root "$dir" "apt-get update -q >/dev/null && DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends $pkgs" \
      >"$dir.install.log" 2>&1 ||
    { echo "platforms: installing the $suite stack failed, see $dir.install.log" >&2; tail -20 "$dir.install.log" >&2; return 1; }
  echo "$pkgs" > "$stamp"
  echo "platforms: $suite root with the FEniCSx stack built in $((SECONDS - t0)) s ($(du -sh "$dir" | cut -f1))" >&2
  echo "$dir"
}

# copy_clone SRC_REPO DEST: a clean clone of the committed HEAD (no results, no venv).
copy_clone() {
  rm -rf "$2"
  git clone -q --no-hardlinks "$1" "$2"
  rm -rf "$2/.git"
}
