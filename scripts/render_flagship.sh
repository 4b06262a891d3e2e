#!/usr/bin/env bash
# installs what is missing, builds, runs the flagship scene (Fig. 3(a) of Shao et al. 2017) and
# renders it with POV-Ray to PNG frames and an MP4 (docs/rendering.md)
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-out/fig3a_cube_on_cloth}"
./scripts/flagship.sh "$out"
rm -rf "$out/render"
./build/soak render "$out"
echo "soak: the flagship movie is $(cd "$out/render" && pwd)/movie.mp4"
