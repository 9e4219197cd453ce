#!/usr/bin/env bash
# Builds test executables under AddressSanitizer + UndefinedBehaviorSanitizer (recovery off: the
# first report aborts the test) with nsp's debug checks on (NSP_DEBUG=1, see core/error.hpp), with
# clang at -O1, into ./build-asan, and runs them. Any sanitizer report or failed debug check fails
# the run. Installs clang and libclang-rt-dev if missing (root or sudo).
# usage: scripts/run-sanitizers.sh [TEST...]: default is the list below; run-tests.sh calls it
# with no arguments.
set -euo pipefail
cd "$(dirname "$0")/.."

# What the sanitizer build runs: the tracking suite (free flight, pdfs, MIS weights, transmittance,
# equiangular sampling), the stability suite (every tracker, majorant kind, bound policy and mode
# at the extremes, and the path estimators), the bidirectional suite (BdptEstimator's vertex
# arrays and strategy weights, grey and per channel, without its "converge" test suite: see
# tests/CMakeLists.txt), the volume-file suite and the debug-mode tests. The fuzz corpus runs under
# the same sanitizers in scripts/run-fuzz.sh (libFuzzer replays the corpus before it fuzzes, and
# the harness drives grid majorants, channel trackers, emissive media and seven estimators), so
# its replay test is not built twice. Left out, to keep CI under 30 minutes on 2 cores (the
# instrumented build costs about 1.5x the Release one): nsp_test_core (constructor validation,
# phase functions, emissive-media sampling), nsp_test_estimators, nsp_test_spectral and
# nsp_test_majorants (every strategy x heuristic x majorant x mode, the slowest to compile); the
# kernels they drive run here through the stability suite and in the fuzzer. Name them as
# arguments to run them too.
default_tests="nsp_test_tracking nsp_test_stability nsp_test_bdpt nsp_test_debug nsp_debug_check_fires nsp_test_volume_files"
read -r -a tests <<< "${*:-${NSP_SANITIZE_TESTS:-$default_tests}}"

# clang, not g++: with the sanitizers on, g++ took several times its Release time on these
# template-heavy files (the fuzz harness over 25 minutes); clang compiles them in about that time.
scripts/install-packages.sh run-sanitizers clang libclang-rt-dev

CC=clang CXX=clang++ NSP_BUILD_DIR=build-asan NSP_CMAKE_ARGS="-DCMAKE_BUILD_TYPE=Debug \
-DCMAKE_CXX_FLAGS_DEBUG=-O1 -DNSP_SANITIZE=address,undefined -DNSP_BUILD_EXAMPLES=OFF \
-DNSP_BUILD_BENCHMARKS=OFF -DNSP_WITH_OPENVDB=OFF" scripts/setup.sh "${tests[@]}"

export ASAN_OPTIONS="halt_on_error=1:abort_on_error=1:detect_leaks=1:detect_stack_use_after_return=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
# A suite may run as several ctest entries (NAME, NAME_part2: see tests/CMakeLists.txt).
regex="^($(IFS='|'; echo "${tests[*]}"))(_part2)?\$"
ctest --test-dir build-asan --output-on-failure --timeout 1500 -j "$(nproc)" -R "$regex"
