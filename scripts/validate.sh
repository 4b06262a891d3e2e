#!/usr/bin/env bash
# the validation suite (validation/validate.py): installs Debian's python3-matplotlib if missing, builds
# soak (scripts/setup.sh) and runs every case; writes docs/validation.md and docs/validation/*.png.
# About 15 minutes on 2 cores. Arguments go to validate.py (--only CASE..., --out DIR).
set -euo pipefail
cd "$(dirname "$0")/.."
if ! dpkg-query -W -f='${Status}' python3-matplotlib 2>/dev/null | grep -q "install ok installed"; then
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq --no-install-recommends python3-matplotlib
fi
./scripts/setup.sh
/usr/bin/python3 validation/validate.py "$@"
