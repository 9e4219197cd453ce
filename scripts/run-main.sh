#!/usr/bin/env bash
# Fresh-machine command 1: set up, build nsp_render (only that target: the tests and benchmarks
# are run-tests.sh's business), and run the main job. Without arguments:
#  1. nsp_render's default run: the grey cloud (set-ups A, B with every estimator; D, a bright
#     sky, with the ones it compares), the chromatic cloud (set-ups C1-C3, rgb, 32x32) with the
#     spectral estimators, the
#     sparse medium (set-up SA, mono, 64x64, 256 spp) with each grey strategy under the global
#     and the grid majorant, the fog lit by a lamp (set-ups F1, F2, F3, mono, 64x64) with
#     tracking + NEE, equiangular + NEE and their three-way MIS, and the flame in the plume
#     (set-up P1, rgb, 64x64) with the collision estimator, emission NEE and their MIS, each under
#     the global and the grid majorant; one efficiency table per set-up and mode, then a summary
#     (per table the best row and the scene's MIS against its best single strategy). In ./out: an
#     EXR per row, a PNG contact sheet per table (SETUP[_mode]_sheet.png, the rows in table order)
#     and a larger PNG picture of each scene (cloud.png, chromatic.png, sparse.png, fog.png,
#     plume.png; --picture-res, 256 by default). docs/renderer.md explains every flag;
#  1b. nsp_room: the cloud over a diffuse floor in an open room under a quad light and a dim sky
#     (the scene with surfaces) with every strategy PathEstimator renders surfaces with, then the
#     chromatic cloud in the room with the spectral estimators, the glowing plume, and the lantern
#     (a lamp boxed above the cloud), grey and chromatic, with the path tracers against BDPT; its
#     five tables and out/room_sheet.png, out/room_rgb_sheet.png, out/room_plume_sheet.png,
#     out/lantern_sheet.png, out/lantern_rgb_sheet.png, out/room.png;
#  1c. nsp_volume: the smoke plume (512^3, .vdb) and the cloud (.vdb) exported and rendered under
#     every majorant (global, grid 16^3 and 64^3, tree on the VDB nodes, adaptive tree), their
#     tables and out/plume_vdb/volume.png, out/cloud_vdb/volume.png; then the plume glowing by its
#     temperature grid (blackbody emission, Rgb) with every strategy, out/plume_fire/volume.png;
#  1d. nsp_transmittance: ratio tracking, residual ratio tracking and unbiased ray marching on 1-D
#     extinction profiles and on shadow rays through the example media and the cloud's .vdb (its
#     NanoVDB tree), and the cost model's pick per medium (three tables, about 8 s);
# With --with-references it then also runs (about 90 s more, which would take the default run past
# five minutes on 2 cores with the renderer's build; README's heavy-tail tables come from it):
#  2. the heavy-tail comparison: the grey-majorant baseline against spectral MIS + NEE (per-channel
#     and global majorant, uniform selection) on the chromatic cloud, 3 runs each at 32x32. The
#     baseline's variance is practically infinite: in a typical run it misses the rare huge
#     samples, so its sample variance understates its error and even the median over runs of
#     var/spl cannot rank it. --reference-spp 2048 therefore first renders a reference image per
#     set-up and mode with a third, finite-variance estimator (spectral tracking + NEE, other
#     seeds) and reports each run's effective variance per sample: spp x the mean squared
#     error against the reference, minus the reference's own noise;
#  3. the same for the two new heavy-tailed set-ups, F1 (tracking + NEE near a lamp inside the
#     fog: a 1/r^2 tail) and P1 (the collision estimator rarely reaches the flame): 3 runs each,
#     2048-spp references (fog: uni-nee-eq-mis_balance_absorb-event; plume:
#     directional-mis_grid_balance_absorb-weight), time x variance from the effective variance.
# Step 1 renders in about 160 s on 2 cores (its pictures about 17 s of it), all three in about
# 270 s, with the build up to date; the renderer's build takes about 2.5 minutes more on a fresh
# machine.
# With other arguments, runs nsp_render once with them instead (see build/examples/nsp_render --help);
# with --room first, nsp_room with the rest (build/examples/nsp_room --help).
set -euo pipefail
cd "$(dirname "$0")/.."
# -O1, not the build type's -O3: the renderers instantiate every combination of policies. On a
# fresh clone on 2 cores (2026-12-05) they built in 233 s at -O1 and 420 s at -O3; the
# renders take about 24% longer at -O1 (set-ups A and B at 48x48, 64 spp, one thread: 11.4 s
# against 9.2 s), every row alike, so the tables' ratios stand. The benchmarks (bench/run.sh)
# build their own -O3 tree.
NSP_CMAKE_ARGS="-DNSP_OPTIMIZE=-O1 ${NSP_CMAKE_ARGS:-}" scripts/setup.sh nsp_room nsp_volume nsp_render nsp_transmittance

references=0
if [ "${1:-}" = --with-references ]; then
    references=1
    shift
fi
if [ "${1:-}" = --room ]; then
    shift
    exec build/examples/nsp_room --out out "$@"
fi
if [ $# -gt 0 ]; then
    exec build/examples/nsp_render --out out "$@"
fi

start=$SECONDS
build/examples/nsp_render --out out
# The scene with surfaces: the cloud over a floor in an open room, grey, chromatic and glowing, and
# the lantern with BDPT (about 75 s).
build/examples/nsp_room --out out --res 64 --spp 128
# Volumes from files: the procedural smoke plume (512^3 voxels, 0.5% of them active) written as .vdb
# and the cloud as .vdb, each rendered under the global, grid 16^3 and 64^3 and tree majorants
# (about 25 s).
build/examples/nsp_volume --export-plume out/plume.vdb
build/examples/nsp_volume out/plume.vdb --compare-majorants --res 96 --spp 64 --density-scale 100 --out out/plume_vdb
build/examples/nsp_volume --export-cloud out/cloud.vdb
build/examples/nsp_volume out/cloud.vdb --compare-majorants --res 96 --spp 64 --density-scale 20 --g 0.9 --out out/cloud_vdb
# The plume's temperature grid: blackbody emission in Rgb, every strategy (about 5 s).
build/examples/nsp_volume out/plume.vdb --temperature temperature --normalize-blackbody --emission-scale 60 \
    --density-scale 100 --majorant tree --res 96 --spp 64 --out out/plume_fire
# The transmittance estimators: 1-D profiles and the example media (about 6 s).
build/examples/nsp_transmittance --volume out/cloud.vdb --density-scale 20
if [ "$references" = 0 ]; then
    echo
    echo "main job: $((SECONDS - start)) s of rendering (scripts/run-main.sh --with-references adds the"
    echo "heavy-tail comparisons against 2048-spp references, about 90 s more)"
    exit 0
fi
echo
echo "Heavy-tail comparison: grey-majorant baseline vs spectral MIS + NEE (per-channel and global"
echo "majorant), 3 runs, effective variance against a 2048-spp reference"
build/examples/nsp_render --scene chromatic --spectral rgb,hero --runs 3 --res 32x32 --spp 128 --no-exr \
    --reference-spp 2048 --selection uniform --no-png \
    --estimators uni-nee-mis_grey_balance_absorb-weight,uni-nee-mis_spectral-mis_absorb-weight
echo
echo "Lamp in fog (F1) and flame in smoke (P1): 3 runs, effective variance against 2048-spp references"
build/examples/nsp_render --scene fog,plume --setup F1,P1 --runs 3 --reference-spp 2048 --no-exr --no-png
echo
echo "main job: $((SECONDS - start)) s of rendering"
