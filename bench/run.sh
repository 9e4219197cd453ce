#!/usr/bin/env bash
# Builds nsp_bench (Release) and runs every benchmark with repetitions in random interleaved
# order, then prints the medians and the tracking / raw lookup-rate ratios (bench/report.py).
# Build directory: $NSP_BENCH_BUILD if set; else ./build if scripts/setup.sh configured it (a
# Release build with benchmarks); else ./build-bench, configured here. Environment:
# NSP_BENCH_REPS (default 5). Extra arguments go to nsp_bench (e.g. --benchmark_filter=Track).
# JSON results: <build>/bench/results.json. The whole run takes about two minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."

is_release_with_benchmarks() {
    [ -f "$1/CMakeCache.txt" ] && grep -q '^NSP_BUILD_BENCHMARKS:BOOL=ON' "$1/CMakeCache.txt" &&
        grep -q '^CMAKE_BUILD_TYPE:STRING=Release' "$1/CMakeCache.txt"
}

build=${NSP_BENCH_BUILD:-}
if [ -z "$build" ]; then
    build=build-bench
    is_release_with_benchmarks build && build=build
fi
if ! is_release_with_benchmarks "$build"; then
    generator=()
    command -v ninja >/dev/null && generator=(-G Ninja)
    cmake -S . -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DNSP_BUILD_BENCHMARKS=ON \
          -DNSP_BUILD_TESTS=OFF -DNSP_BUILD_EXAMPLES=OFF >/dev/null
fi
cmake --build "$build" --target nsp_bench --parallel "$(nproc)"

json=$build/bench/results.json
"$build/bench/nsp_bench" --benchmark_repetitions="${NSP_BENCH_REPS:-5}" \
    --benchmark_enable_random_interleaving=true \
    --benchmark_report_aggregates_only=true \
    --benchmark_out="$json" --benchmark_out_format=json "$@"
echo
python3 bench/report.py "$json"
