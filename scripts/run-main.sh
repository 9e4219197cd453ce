#!/usr/bin/env bash
# Fresh-machine command 1: set up, build, and run the main job. Without arguments:
#  1. nsp_render's default run: the grey cloud (set-ups A, B) with every estimator and the
#     chromatic cloud (set-ups C1, C2, rgb and hero) with the spectral estimators; EXRs in ./out,
#     one efficiency table per set-up and mode;
#  2. the heavy-tail comparison: the grey-majorant baseline against spectral MIS + NEE (uniform and
#     luminance selection) on the chromatic cloud, 5 runs each at low resolution, reporting the
#     median over the runs (the sample variance of an infinite-variance estimator is itself
#     unreliable, so one run cannot rank them).
# With arguments, runs nsp_render once with them instead (see build/examples/nsp_render --help).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh

if [ $# -gt 0 ]; then
    exec build/examples/nsp_render --out out "$@"
fi

start=$SECONDS
build/examples/nsp_render --out out
echo
echo "Heavy-tail comparison: grey-majorant baseline vs spectral MIS + NEE, median of 5 runs"
build/examples/nsp_render --scene chromatic --runs 5 --res 32x32 --spp 128 --no-exr \
    --estimators uni-nee-mis_grey_balance_absorb-weight,uni-nee-mis_spectral-mis_absorb-weight
echo
echo "main job: $((SECONDS - start)) s of rendering"
