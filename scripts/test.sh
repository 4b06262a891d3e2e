#!/usr/bin/env bash
# installs what is missing, builds, and runs the whole test suite: once as built for this machine's
# CPU (build/), once built without -march=native (build-portable/), so the scalar code paths that an
# AVX-512 machine never takes (neighbour search, coupling walk, PBF pair sums) are compiled and tested
# too. SOAK_SKIP_PORTABLE=1 skips the second build.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
ctest --test-dir build --output-on-failure -j "$(nproc)"
if [[ "${SOAK_SKIP_PORTABLE:-0}" != 1 ]]; then
  cmake -S . -B build-portable -G Ninja -DCMAKE_BUILD_TYPE=Release -DSOAK_NATIVE=OFF
  cmake --build build-portable -j "$(nproc)"
  ctest --test-dir build-portable --output-on-failure -j "$(nproc)"
fi
