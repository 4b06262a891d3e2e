#!/usr/bin/env bash
# installs what is missing, builds, and runs the whole test suite: once as built for this machine's
# CPU (build/), once built without -march=native (build-portable/), so the scalar code paths that an
# AVX-512 machine never takes (neighbour search, coupling walk, PBF pair sums) are compiled and tested
# too. SOAK_SKIP_PORTABLE=1 skips the second build. The libFuzzer targets are built with clang in
# build-fuzz/ (scripts/fuzz.sh), and the suite runs each for a few seconds.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
# the fuzz targets are built before the suite, which runs them briefly (77: clang's fuzzer runtime missing)
./scripts/fuzz.sh --build || [[ $? -eq 77 ]]
# why a test was skipped: the line it printed ("SKIPPED: ..." or "soak: fuzz: skipped: ...") in
# ctest's log, since ctest shows only that it was
skipped() { grep -hE "^SKIPPED: |: skipped: " "$1/Testing/Temporary/LastTest.log" 2> /dev/null || true; }
ctest --test-dir build --output-on-failure -j "$(nproc)"
skipped build
if [[ "${SOAK_SKIP_PORTABLE:-0}" != 1 ]]; then
  cmake -S . -B build-portable -G Ninja -DCMAKE_BUILD_TYPE=Release -DSOAK_NATIVE=OFF
  cmake --build build-portable -j "$(nproc)"
  ctest --test-dir build-portable --output-on-failure -j "$(nproc)"
  skipped build-portable
fi
