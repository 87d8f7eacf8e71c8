#!/usr/bin/env bash
# The README's second command: install dependencies, build, run every test (CTest).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh"
cd "${LOOM_BUILD_DIR:-$root/build}"
ctest --output-on-failure -j "${LOOM_JOBS:-$(nproc)}" --timeout 900
