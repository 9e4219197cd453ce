#!/usr/bin/env bash
# Fresh-machine command 2: set up, build, and run the whole test suite (ctest).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
ctest --test-dir build --output-on-failure --timeout 1500 -j "$(nproc)"
