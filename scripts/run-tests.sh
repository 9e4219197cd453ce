#!/usr/bin/env bash
# Fresh-machine command 2: set up, build and run the whole test suite. CI (.ci/run) runs exactly
# this. Three stages, each failing the run on its first failure:
#  1. the Release build of everything (tests, examples, benchmarks) and ctest: the doctest suites,
#     the stability suite, the fuzz corpus replay, the debug-mode checks, the compile-failure
#     tests and the package-consumer test;
#  2. scripts/run-sanitizers.sh: the suites it lists rebuilt under AddressSanitizer +
#     UndefinedBehaviorSanitizer with debug checks on, and run;
#  3. scripts/run-fuzz.sh: the libFuzzer target built with clang and run for NSP_FUZZ_SECONDS
#     (default 120) from the checked-in corpus.
# NSP_SKIP_SANITIZERS=1 or NSP_FUZZ_SECONDS=0 skip stages 2 or 3 (for a quick local run; CI runs all).
set -euo pipefail
cd "$(dirname "$0")/.."
start=$SECONDS
scripts/setup.sh
ctest --test-dir build --output-on-failure --timeout 1500 -j "$(nproc)"
echo "run-tests: release build and ctest done after $((SECONDS - start)) s"
if [ "${NSP_SKIP_SANITIZERS:-0}" != 1 ]; then
    scripts/run-sanitizers.sh
    echo "run-tests: sanitizers done after $((SECONDS - start)) s"
fi
if [ "${NSP_FUZZ_SECONDS:-120}" != 0 ]; then
    scripts/run-fuzz.sh
    echo "run-tests: fuzzing done after $((SECONDS - start)) s"
fi
echo "run-tests: all stages passed in $((SECONDS - start)) s"
