#!/usr/bin/env bash
# The moving-body garment on the mannequin and on its OBJ sequence, side by side: exports the
# mannequin of scenes/garment_tshirt_moving.json as scenes/obj_body/frames/body_NNNN.obj (soak
# export-body), runs that scene and scenes/obj_body/garment_tshirt_obj_body.json (the same shirt on
# the exported frames, a meshSequence collider) and prints, every 30 frames, the shirt's lowest point,
# mean height and mean distance to the body, and the time per frame of each (docs/mannequin.md,
# "Animated bodies").
#
#   scripts/obj-body.sh [--frames N] [--work DIR]
#
# --frames N: frames to run (default 150, the scenes' 5 s). --work DIR: where the runs go (default
# /tmp/soak-obj-body). Environment: SOAK (default build/soak), THREADS (default 1 per run; the two
# runs go side by side).
set -euo pipefail
cd "$(dirname "$0")/.."
soak="${SOAK:-$PWD/build/soak}"
threads="${THREADS:-1}"
frames=150
work=/tmp/soak-obj-body
while [ $# -gt 0 ]; do
  case "$1" in
    --frames) frames="$2"; shift 2 ;;
    --work) work="$2"; shift 2 ;;
    -h|--help) sed -n '2,14p' "$0"; exit 0 ;;
    *) echo "obj-body.sh: unknown argument $1" >&2; exit 1 ;;
  esac
done
"$soak" export-body scenes/garment_tshirt_moving.json -o scenes/obj_body/frames --frames $((frames + 1)) --overwrite
mkdir -p "$work"
export OMP_WAIT_POLICY="${OMP_WAIT_POLICY:-PASSIVE}"
"$soak" run scenes/garment_tshirt_moving.json -o "$work/mannequin" --frames "$frames" --threads "$threads" \
  --overwrite --quiet &
"$soak" run scenes/obj_body/garment_tshirt_obj_body.json -o "$work/obj" --frames "$frames" --threads "$threads" \
  --overwrite --quiet &
wait %1
wait %2
/usr/bin/python3 - "$work" <<'PY'
import json, sys
work = sys.argv[1]
runs = {name: [json.loads(l) for l in open(f"{work}/{name}/stats.jsonl")] for name in ("mannequin", "obj")}
print(f"{'frame':>5} | {'lowest point (m)':>19} | {'mean height (m)':>17} | {'body distance (cm)':>19} | {'s per frame':>13}")
print(f"{'':>5} | {'mannequin':>9} {'obj':>9} | {'mannequin':>8} {'obj':>8} | {'mannequin':>9} {'obj':>9} | {'mannequin':>6} {'obj':>6}")
n = min(len(r) for r in runs.values())
for f in list(range(30, n, 30)) + ([n - 1] if (n - 1) % 30 else []):
    a, b = (runs[k][f] for k in ("mannequin", "obj"))
    ga, gb = a["garment"], b["garment"]
    print(f"{f:>5} | {ga['lowestPoint']:9.4f} {gb['lowestPoint']:9.4f} | {ga['meanHeight']:8.4f} {gb['meanHeight']:8.4f} | "
          f"{100 * ga['meanColliderDistance']:9.2f} {100 * gb['meanColliderDistance']:9.2f} | "
          f"{a['ms']['total'] / 1000:6.2f} {b['ms']['total'] / 1000:6.2f}")
PY
