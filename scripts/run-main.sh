#!/usr/bin/env bash
# Fresh-machine command 1: set up, build, and run the main job: render the default scene in both
# light set-ups with every estimator, write EXRs to ./out and print the efficiency table.
# Extra arguments go to the renderer (see build/examples/nsp_render --help).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
build/examples/nsp_render --out out "$@"
