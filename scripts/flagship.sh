#!/usr/bin/env bash
# installs what is missing, builds, and runs the flagship scene (Fig. 3(a) of Shao et al. 2017)
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
out="${1:-out/fig3a_cube_on_cloth}"
./build/soak run scenes/fig3a_cube_on_cloth.json -o "$out" --overwrite
echo "soak: the flagship scene's frames are in $(cd "$out" && pwd)"
