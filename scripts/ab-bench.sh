#!/usr/bin/env bash
# Times two soak binaries against each other on bench entries: A and B alternate, scene by scene,
# for ROUNDS rounds, so both see the same spells of a shared machine; prints each run's ms per step
# (median of the timed steps) and CPU seconds, then the median over rounds of both and their ratio.
#
#   scripts/ab-bench.sh BINARY_A BINARY_B SCENE...     (bench/benchmarks.json entry names)
#
# Environment: ROUNDS (default 3), THREADS (default 2). Needs python3 for the summary and
# /usr/bin/time (Debian's package time) for the CPU seconds.
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 3 ] || { echo "usage: $0 BINARY_A BINARY_B SCENE..." >&2; exit 1; }
a="$1" b="$2"
shift 2
rounds="${ROUNDS:-3}"
threads="${THREADS:-2}"
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT
for ((r = 1; r <= rounds; ++r)); do
  for scene in "$@"; do
    for side in A B; do
      bin="$a"
      [ "$side" = B ] && bin="$b"
      /usr/bin/time -f "%U %S" -o "$dir/time" "$bin" bench --scene "$scene" --threads "$threads" --quiet \
        --json "$dir/$scene.$side.$r.json" > /dev/null
      awk '{print $1 + $2}' "$dir/time" > "$dir/$scene.$side.$r.cpu"
    done
  done
done
python3 - "$dir" "$rounds" "$@" <<'EOF'
import json, statistics, sys
d, rounds, scenes = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
def ms(scene, side, r):
    return json.load(open(f"{d}/{scene}.{side}.{r}.json"))["results"][0]["msPerStepMedian"]["total"]
print(f"{'scene':18} {'A ms/step (rounds)':32} {'B ms/step (rounds)':32} {'B/A median':>10}  CPU s A / B")
for s in scenes:
    a = [ms(s, "A", r) for r in range(1, rounds + 1)]
    b = [ms(s, "B", r) for r in range(1, rounds + 1)]
    ca = [float(open(f"{d}/{s}.A.{r}.cpu").read()) for r in range(1, rounds + 1)]
    cb = [float(open(f"{d}/{s}.B.{r}.cpu").read()) for r in range(1, rounds + 1)]
    fa = " ".join(f"{x:.1f}" for x in a)
    fb = " ".join(f"{x:.1f}" for x in b)
    print(f"{s:18} {fa:32} {fb:32} {statistics.median(b) / statistics.median(a):10.3f}  "
          f"{statistics.median(ca):.1f} / {statistics.median(cb):.1f}")
EOF
