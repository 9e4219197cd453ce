#!/usr/bin/env bash
# Fresh-machine command 2: set up, build and run the whole test suite. CI (.ci/run) runs exactly
# this. Three stages; the run fails if any of them does:
#  1. the build of the tests and the example renderer into ./build-tests, and ctest: the doctest
#     suites, the stability suite, the fuzz corpus replay, the debug-mode tests, the compile-failure
#     tests and the package-consumer test. To keep CI under 30 minutes on 2 cores it compiles at
#     -O1 -DNDEBUG (NSP_OPTIMIZE: about 6 minutes less build than -O3, about 10% more test time)
#     into its own directory, so run-main.sh's -O3 renderer in ./build is untouched, and it does not
#     build the benchmarks (bench/run.sh does);
#  2. scripts/run-sanitizers.sh: suites rebuilt under AddressSanitizer + UndefinedBehaviorSanitizer
#     with debug checks on, and run;
#  3. scripts/run-fuzz.sh: the libFuzzer target built with clang and run from the checked-in
#     corpus over a fixed sequence (seed 1, 30000 inputs, at most NSP_FUZZ_SECONDS, default 120;
#     NSP_FUZZ_SECONDS=0 skips the stage).
# Stages 2 and 3 run side by side (each is mostly one long single-threaded process), with their
# output printed when both are done (a failing stage's last).
# NSP_SKIP_SANITIZERS=1 skips stage 2 (for a quick local run).
set -euo pipefail
cd "$(dirname "$0")/.."
start=$SECONDS
NSP_BUILD_DIR=build-tests NSP_CMAKE_ARGS="-DNSP_BUILD_BENCHMARKS=OFF -DNSP_OPTIMIZE=-O1" scripts/setup.sh
ctest --test-dir build-tests --output-on-failure --timeout 1500 -j "$(nproc)"
echo "run-tests: release build and ctest done after $((SECONDS - start)) s"

sanitize=1 fuzz=1
[ "${NSP_SKIP_SANITIZERS:-0}" != 1 ] || sanitize=0
export NSP_FUZZ_SECONDS="${NSP_FUZZ_SECONDS:-120}"
[ "$NSP_FUZZ_SECONDS" != 0 ] || fuzz=0
[ $((sanitize + fuzz)) -gt 0 ] || exit 0

# Both stages need clang; install it once here, not from both at the same time (apt's lock).
scripts/install-packages.sh run-tests clang libclang-rt-dev

logs="$(mktemp -d "${TMPDIR:-/tmp}/nsp-tests.XXXXXX")"
san_status=0 fuzz_status=0
[ "$sanitize" = 0 ] || { scripts/run-sanitizers.sh >"$logs/sanitizers.log" 2>&1 & san_pid=$!; }
[ "$fuzz" = 0 ] || { scripts/run-fuzz.sh >"$logs/fuzz.log" 2>&1 & fuzz_pid=$!; }
[ "$sanitize" = 0 ] || wait "$san_pid" || san_status=$?
[ "$fuzz" = 0 ] || wait "$fuzz_pid" || fuzz_status=$?
# A failing stage's log is printed last, so that the end of the output (all a CI page may keep)
# shows the failure rather than the other stage's progress.
order="sanitizers fuzz"
[ "$san_status" = 0 ] || order="fuzz sanitizers"
for stage in $order; do
    [ -f "$logs/$stage.log" ] || continue
    echo "===== run-tests: $stage ====="
    cat "$logs/$stage.log"
done
echo "run-tests: sanitizers exit $san_status, fuzzer exit $fuzz_status, after $((SECONDS - start)) s"
[ "$san_status" = 0 ] && [ "$fuzz_status" = 0 ] || exit 1
echo "run-tests: all stages passed in $((SECONDS - start)) s"
