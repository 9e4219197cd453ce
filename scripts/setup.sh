#!/usr/bin/env bash
# Installs the Debian packages nsp builds with, skipping those already present, then configures
# and builds into ./build. Needs root (or sudo) only when a package is missing.
# usage: scripts/setup.sh [TARGET...]: without arguments builds everything (run-tests.sh and CI
# rely on that); with targets, only those (run-main.sh builds nsp_render alone, which on a fresh
# 2-core machine takes about a minute instead of the whole test suite's build).
# Environment: NSP_BUILD_DIR (default build) and NSP_CMAKE_ARGS (extra configure arguments without
# spaces inside one argument, after the defaults so they win): run-sanitizers.sh uses both.
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/install-packages.sh setup cmake ninja-build g++ libglm-dev libeigen3-dev libopenexr-dev doctest-dev libbenchmark-dev libcli11-dev libstb-dev \
    libnanovdb-dev zlib1g-dev libblosc-dev libopenvdb-dev libboost-iostreams-dev

generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
build_dir="${NSP_BUILD_DIR:-build}"
read -r -a extra_args <<< "${NSP_CMAKE_ARGS:-}"
cmake -S . -B "$build_dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release "${extra_args[@]}"
targets=()
[ $# -eq 0 ] || targets=(--target "$@")
cmake --build "$build_dir" --parallel "$(nproc)" "${targets[@]}"
