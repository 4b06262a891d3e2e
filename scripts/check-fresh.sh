#!/usr/bin/env bash
# The fresh-machine check: builds a minimal Debian 12 root (debootstrap --variant=minbase, from the
# Debian mirror this machine's own apt sources name), puts a clean clone of this checkout's HEAD in it
# (at this checkout's own path inside the root), and runs the README's two commands there, one after the
# other (the second reuses the packages and the build of the first), printing how long each took. It
# fails when either command fails, so a package missing from scripts/setup.sh fails CI (.ci/run calls
# this after the test suite).
#
# The root borrows this machine's ccache directory (bind-mounted), so an object compiled here from the
# same command line, compiler and headers is not compiled again there; ccache still compiles whatever
# differs, and a header the root lacks is a miss that reaches the compiler and fails as it would
# without the cache. The clone sits at the same path so that the command lines match. The cache's hits
# and misses in the root are printed at the end.
#
# Needs root (debootstrap, chroot, mount). Only committed work is checked: the clone is of HEAD.
#
# Environment:
#   SOAK_FRESH_DIR     where the root is built (default: a new folder under /tmp); removed at the end
#   SOAK_FRESH_KEEP=1  keep the root afterwards (to look inside; it takes a few GB)
#   SOAK_FRESH_MIRROR  the Debian mirror to use instead of the one in this machine's apt sources
#   SOAK_FRESH_TIMES   also write the two timings, as JSON, to this file
#   SOAK_FRESH_CCACHE=0  do not lend this machine's ccache directory to the root (every object compiled)
set -euo pipefail
cd "$(dirname "$0")/.."
repo="$(pwd)"
suite=bookworm

fail() { echo "check-fresh: $*" >&2; exit 1; }

[ "$(id -u)" -eq 0 ] || fail "must run as root (debootstrap, chroot and mount need it)"
git -C "$repo" rev-parse --verify -q HEAD > /dev/null || fail "$repo is not a git checkout with a commit"

if ! command -v debootstrap > /dev/null; then
  echo "check-fresh: installing debootstrap"
  { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends debootstrap; } ||
    fail "cannot build a fresh root: debootstrap is not installed and apt-get could not install it"
fi

# The machine's Debian sources: deb822 files (sources.list.d/*.sources) and one-line lists.
# Prints the files that name the Debian archive for $suite (not the security or updates archives).
debian_source_files() {
  local f
  for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list /etc/apt/sources.list.d/*.sources; do
    [ -f "$f" ] && grep -Eq "^[[:space:]]*(deb[[:space:]].*[[:space:]]$suite([[:space:]]|$)|Suites:.*(^|[[:space:]])$suite([[:space:]]|$))" "$f" &&
      echo "$f"
  done
  return 0
}
mapfile -t source_files < <(debian_source_files)

# The mirror: the first URI given for the suite itself.
mirror="${SOAK_FRESH_MIRROR:-}"
if [ -z "$mirror" ] && [ ${#source_files[@]} -gt 0 ]; then
  mirror="$(awk -v suite="$suite" '
    /^[[:space:]]*deb[[:space:]]/ { for (i = 2; i <= NF; i++) if ($i == suite) { u = $(i-1); if (u ~ /^\[/) u = $(i-2); print u; exit } }
    /^[[:space:]]*$/ { uri = ""; suites = "" }
    /^URIs:/ { uri = $2 }
    /^Suites:/ { for (i = 2; i <= NF; i++) if ($i == suite) suites = suite }
    uri != "" && suites != "" { print uri; exit }' "${source_files[@]}")"
fi
[ -n "$mirror" ] || fail "cannot build a fresh root: no Debian mirror for $suite in /etc/apt/sources.list{,.d/} (set SOAK_FRESH_MIRROR)"

dir="${SOAK_FRESH_DIR:-$(mktemp -d /tmp/soak-fresh.XXXXXX)}"
root="$dir/root"
mounted=()
cleanup() {
  local m
  for m in "${mounted[@]}"; do umount -l "$m" 2> /dev/null || true; done
  if [ "${SOAK_FRESH_KEEP:-0}" = 1 ]; then
    echo "check-fresh: the root is kept in $root"
  elif grep -q " $root/" /proc/self/mounts; then
    echo "check-fresh: something is still mounted under $root; not removing $dir" >&2
  else
    rm -rf --one-file-system "$dir"
  fi
}
trap cleanup EXIT
mkdir -p "$dir"
[ ! -e "$root" ] || fail "$root exists already: remove it or choose another SOAK_FRESH_DIR"

seconds() { date +%s; }
t0=$(seconds)
echo "check-fresh: building a minimal Debian 12 ($suite) root in $root from $mirror"
debootstrap --variant=minbase "$suite" "$root" "$mirror" > "$dir/debootstrap.log" 2>&1 || {
  tail -n 20 "$dir/debootstrap.log" >&2
  fail "cannot build a fresh root: debootstrap failed (log above; mirror $mirror)"
}
echo "check-fresh: root built in $(( $(seconds) - t0 )) s"

# The root reaches the mirror as this machine does: its Debian sources (so the security and updates
# archives are there too, as on an installed Debian 12), the apt settings for reaching them (proxy,
# Valid-Until of a snapshot mirror), and name resolution. Nothing else of this machine goes in.
if [ ${#source_files[@]} -gt 0 ] && [ -z "${SOAK_FRESH_MIRROR:-}" ]; then
  rm -f "$root/etc/apt/sources.list"
  for f in "${source_files[@]}"; do cp "$f" "$root/etc/apt/sources.list.d/$(basename "$f")"; done
  mv -f "$root/etc/apt/sources.list.d/sources.list" "$root/etc/apt/sources.list" 2> /dev/null || true
fi
for f in /etc/apt/apt.conf.d/*; do
  [ -f "$f" ] && grep -Eqi '^[[:space:]]*Acquire::(http|https)::Proxy|Check-Valid-Until|Check-Date' "$f" &&
    cp "$f" "$root/etc/apt/apt.conf.d/"
done
cp -L /etc/resolv.conf "$root/etc/resolv.conf" 2> /dev/null || true
cp /etc/hosts "$root/etc/hosts"

mount -t proc proc "$root/proc" && mounted+=("$root/proc")
mount -t tmpfs tmpfs "$root/dev/shm" && mounted+=("$root/dev/shm")
# /sys with its cgroup mount, as a machine has it: slurmd (tests/slurm/) will not start without it
mount --rbind /sys "$root/sys" && mount --make-rslave "$root/sys" && mounted+=("$root/sys")

git clone --quiet --no-hardlinks "$repo" "$root$repo"
echo "check-fresh: a clean clone of $(git -C "$repo" rev-parse --short HEAD) is in $repo of the root"

# this machine's compile cache, at the same path in the root (empty where ccache is not installed here)
cache_dir=""
if [ "${SOAK_FRESH_CCACHE:-1}" != 0 ] && command -v ccache > /dev/null; then
  cache_dir="$(ccache -k cache_dir)"
  mkdir -p "$cache_dir" "$root$cache_dir"
  mount --bind "$cache_dir" "$root$cache_dir" && mounted+=("$root$cache_dir")
  ccache --zero-stats > /dev/null
  echo "check-fresh: the root compiles through this machine's ccache directory $cache_dir"
fi

# runs one README command in the root, with an environment like a fresh login's
run_in_root() {
  local cache_env=()
  [ -n "$cache_dir" ] && cache_env=(CCACHE_DIR="$cache_dir")
  chroot "$root" /usr/bin/env -i HOME=/root LANG=C.UTF-8 TERM=dumb CI="${CI:-}" \
    SOAK_SKIP_PORTABLE="${SOAK_SKIP_PORTABLE:-0}" "${cache_env[@]}" \
    PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    bash -c "cd $(printf %q "$repo") && $1"
}

times=()
for cmd in ./scripts/flagship.sh ./scripts/test.sh; do
  echo "check-fresh: running $cmd on the fresh root"
  t=$(seconds)
  if ! run_in_root "$cmd"; then
    fail "$cmd failed on a fresh minimal Debian 12 after $(( $(seconds) - t )) s (its output is above)"
  fi
  times+=("$(( $(seconds) - t ))")
done

echo "check-fresh: on a fresh minimal Debian 12 ($(nproc) cores):"
echo "check-fresh:   ./scripts/flagship.sh  ${times[0]} s"
echo "check-fresh:   ./scripts/test.sh      ${times[1]} s (after the first; it reuses its packages and build)"
if [ -n "$cache_dir" ]; then
  # objects taken from the cache (direct or preprocessed hits) against those compiled in the root
  ccache --print-stats | awk -F'\t' '$1 ~ /^(direct_cache_hit|preprocessed_cache_hit)$/ { h += $2 }
    $1 == "cache_miss" { m = $2 } END { printf "check-fresh:   ccache: %d objects from the cache, %d compiled\n", h, m }'
fi
if [ -n "${SOAK_FRESH_TIMES:-}" ]; then
  printf '{"cores": %d, "flagship_s": %d, "test_s": %d, "commit": "%s"}\n' "$(nproc)" "${times[0]}" "${times[1]}" \
    "$(git -C "$repo" rev-parse --short HEAD)" > "$SOAK_FRESH_TIMES"
fi
echo "check-fresh: passed"
