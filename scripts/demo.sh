#!/usr/bin/env bash
# The README's first command: install dependencies, build, run `loom demo` on the bundled example.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh"
"${LOOM_BUILD_DIR:-$root/build}/app/loom" demo "$@"
