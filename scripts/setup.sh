#!/usr/bin/env bash
# installs the Debian 12 packages soak needs (only those missing) and builds it in Release into build/.
# The list is complete for a fresh minimal Debian 12 (apt-get --no-install-recommends pulls no extras):
# scripts/check-fresh.sh proves it in a debootstrap root, and CI runs that check.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(g++ cmake ninja-build pkg-config libeigen3-dev nlohmann-json3-dev libcli11-dev libfmt-dev
          libtinyobjloader-dev libgtest-dev libgmock-dev
          libopenvdb-dev libboost-iostreams-dev zlib1g-dev libcgal-dev povray ffmpeg
          python3-dev pybind11-dev python3-numpy python3-pytest python3-matplotlib
          clang libclang-rt-14-dev libomp-14-dev
          munge slurmctld slurmd slurm-client ccache)
# zlib1g-dev: OpenVDB's CMake module (FindOpenVDB.cmake) requires ZLIB but its package does not depend on it.
# libcgal-dev: the sewing patterns' triangulation (src/world/pattern.cpp)
# python3-*, pybind11-dev: the Python module (python/), its tests (pytest) and example (matplotlib)
# clang, libclang-rt-14-dev (libFuzzer, the sanitizers) and libomp-14-dev (clang's OpenMP): the fuzz
# targets of tests/fuzz/, built by scripts/fuzz.sh
# munge, slurm*: soak sweep --slurm's test (tests/slurm/), which starts a single-node Slurm of its own
# ccache: the builds compile through it (CMakeLists.txt), so a rebuild compiles only what changed and
# scripts/check-fresh.sh's fresh root reuses what the suite's builds compiled
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "soak: installing ${missing[*]}"
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j "$(nproc)"
