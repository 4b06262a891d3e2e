#!/usr/bin/env bash
# the libFuzzer targets of tests/fuzz/ (the scene loader, the OBJ reader): builds them with clang,
# AddressSanitizer and UndefinedBehaviorSanitizer in build-fuzz/ (cmake -DSOAK_FUZZ=ON), then runs
# each on its seed corpus (tests/fuzz/corpus/<target>) plus what earlier runs found (build-fuzz/corpus/).
#   scripts/fuzz.sh                 every target for 600 s
#   scripts/fuzz.sh 20 scene        the scene loader for 20 s
#   scripts/fuzz.sh --build         build only
# A crash leaves its input in build-fuzz/crash-<target>-*; replay it with build-fuzz/fuzz_<target> FILE.
# Exits 77 (ctest's skip) when clang or its fuzzer runtime (libclang-rt-14-dev) is missing.
set -euo pipefail
cd "$(dirname "$0")/.."

cxx="${SOAK_FUZZ_CXX:-clang++}"
if ! command -v "$cxx" > /dev/null; then
  echo "soak: fuzz: skipped: $cxx not found (scripts/setup.sh installs clang)"
  exit 77
fi
runtime="$("$cxx" -print-file-name=libclang_rt.fuzzer-x86_64.a)"
if [[ ! -f "$runtime" ]]; then
  echo "soak: fuzz: skipped: clang's libFuzzer runtime (libclang_rt.fuzzer-x86_64.a, Debian package" \
       "libclang-rt-14-dev) is not installed; scripts/setup.sh installs it"
  exit 77
fi

cmake -S . -B build-fuzz -G Ninja -DSOAK_FUZZ=ON -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=Debug > /dev/null
cmake --build build-fuzz -j "${SOAK_FUZZ_JOBS:-$(nproc)}"
[[ "${1:-}" == "--build" ]] && exit 0

seconds="${1:-600}"
shift || true
targets=("$@")
[[ ${#targets[@]} -eq 0 ]] && targets=(scene obj)
for t in "${targets[@]}"; do
  mkdir -p "build-fuzz/corpus/$t"
  echo "soak: fuzz: $t for $seconds s"
  # passive waits: the loader's parallel loops must not spin on a machine shared with other tests
  OMP_WAIT_POLICY=PASSIVE OMP_NUM_THREADS=1 "build-fuzz/fuzz_$t" "build-fuzz/corpus/$t" "tests/fuzz/corpus/$t" \
    -max_total_time="$seconds" -max_len=16384 -timeout=30 -rss_limit_mb=4096 \
    -artifact_prefix="build-fuzz/crash-$t-" -print_final_stats=1 2>&1 | grep -v "^#[0-9]" || {
    echo "soak: fuzz: $t found a crash (input in build-fuzz/crash-$t-*)"
    exit 1
  }
done
