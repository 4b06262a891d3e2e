#!/usr/bin/env bash
# Checks that a change leaves every simulated result as it was: builds BASE (a git revision) and the
# working tree, runs each scene of scenes/ and bench/ for FRAMES frames with 1 and 2 threads in both,
# and compares every output file byte for byte (cmp). stats.jsonl is compared without its timings
# (ms, msParts, msPerStep); run.json (wall times) is not compared.
#
#   scripts/compare-frames.sh BASE [SCENE.json ...]
#
# Environment: FRAMES (default 10), THREADS (default "1 2"), COMPARE_DIR (default out/compare),
# BASE_ONLY=1 (only build and run the base, e.g. while the working tree is being changed).
# The base build (build-base/) and its frames (COMPARE_DIR/base-SHA/) are kept, so a second run only
# simulates the working tree. Needs python3 for the stats comparison. Exit 1 when anything differs.
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 1 ] || { echo "usage: $0 BASE [SCENE.json ...]" >&2; exit 1; }
base_sha="$(git rev-parse --verify "$1^{commit}")"
shift
frames="${FRAMES:-10}"
threads="${THREADS:-1 2}"
dir="${COMPARE_DIR:-out/compare}"
if [ $# -gt 0 ]; then scenes=("$@"); else scenes=(scenes/*.json bench/water_block_*.json); fi

# the base, built once in its own worktree
if [ ! -x build-base/soak ] || [ "$(cat build-base/SHA 2> /dev/null)" != "$base_sha" ]; then
  rm -rf build-base
  git worktree prune
  git worktree add --detach build-base/src "$base_sha" > /dev/null
  cmake -S build-base/src -B build-base/build -G Ninja -DCMAKE_BUILD_TYPE=Release -DSOAK_BUILD_TESTS=OFF > /dev/null
  cmake --build build-base/build --target soak -j "$(nproc)"
  cp build-base/build/soak build-base/soak
  echo "$base_sha" > build-base/SHA
fi
[ "${BASE_ONLY:-0}" = 1 ] || cmake --build build --target soak -j "$(nproc)"

# runs one scene with one binary into $1 unless it is there already
run_scene() {
  local bin="$1" scene="$2" out="$3" t="$4"
  [ -f "$out/done" ] && return 0
  "$bin" run "$scene" -o "$out" --frames "$frames" --threads "$t" --overwrite --quiet
  touch "$out/done"
}

# stats.jsonl without the timings
stats_sans_ms() {
  python3 -c '
import json, sys
for line in open(sys.argv[1]):
    j = json.loads(line)
    for k in ("ms", "msParts", "msPerStep"): j.pop(k, None)
    print(json.dumps(j, sort_keys=True))' "$1"
}

differ=0
for scene in "${scenes[@]}"; do
  name="$(basename "$scene" .json)"
  for t in $threads; do
    b="$dir/base-${base_sha:0:12}/$name/t$t"
    n="$dir/new/$name/t$t"
    rm -rf "$n"
    run_scene build-base/soak "$scene" "$b" "$t"
    [ "${BASE_ONLY:-0}" = 1 ] && { echo "base      $name, $t thread(s)"; continue; }
    run_scene build/soak "$scene" "$n" "$t"
    bad=()
    for f in "$b"/*; do
      fn="$(basename "$f")"
      case "$fn" in
        run.json|done) ;;
        stats.jsonl) cmp -s <(stats_sans_ms "$f") <(stats_sans_ms "$n/$fn") || bad+=("$fn") ;;
        *) cmp -s "$f" "$n/$fn" || bad+=("$fn") ;;
      esac
    done
    for f in "$n"/*; do [ -e "$b/$(basename "$f")" ] || bad+=("$(basename "$f") (new)"); done
    if [ ${#bad[@]} -eq 0 ]; then
      echo "same      $name, $t thread(s), $(ls "$b" | wc -l) files"
    else
      echo "DIFFERENT $name, $t thread(s): ${bad[*]:0:6}"
      differ=1
    fi
  done
done
exit $differ
