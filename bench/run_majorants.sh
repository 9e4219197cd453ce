#!/usr/bin/env bash
# The majorant sweep in one command: builds nsp_bench_majorants (Release), runs every row of
# bench/bench_majorants.cpp with 5 repetitions in random interleaved order (fixed iteration
# counts; the counters are the same in every repetition, times are medians), writes
# bench/majorants.json and plots it to bench/majorants.png (bench/plot_majorants.py, matplotlib).
# About 3-4.5 minutes on 2 cores (the 4096-spp reference images take ~30 s of it).
#
# Build directory: $NSP_BENCH_BUILD if set, else ./build-bench (configured here if needed).
# Environment: NSP_BENCH_REPS (default 5), NSP_BENCH_JOBS (default nproc). Extra arguments go to
# the benchmark binary (e.g. --benchmark_filter=sparse).
set -euo pipefail
cd "$(dirname "$0")/.."

build=${NSP_BENCH_BUILD:-build-bench}
if [ ! -f "$build/CMakeCache.txt" ]; then
    generator=()
    command -v ninja >/dev/null && generator=(-G Ninja)
    cmake -S . -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DNSP_BUILD_BENCHMARKS=ON \
          -DNSP_BUILD_TESTS=OFF -DNSP_BUILD_EXAMPLES=OFF >/dev/null
fi
cmake --build "$build" --target nsp_bench_majorants --parallel "${NSP_BENCH_JOBS:-$(nproc)}"

code=unknown
if git rev-parse --git-dir >/dev/null 2>&1; then
    code=$(git rev-parse --short HEAD)
    for d in include examples bench; do
        [ -z "$(git status --porcelain -- "$d")" ] || code="$code+local-$d"
    done
fi

"$build/bench/nsp_bench_majorants" --benchmark_repetitions="${NSP_BENCH_REPS:-5}" \
    --benchmark_enable_random_interleaving=true --benchmark_report_aggregates_only=true \
    --benchmark_context=code="$code" \
    --benchmark_out=bench/majorants.json --benchmark_out_format=json "$@"
# matplotlib: the first python3 on PATH that has it (a pyenv python may not see Debian's).
py=python3
python3 -c 'import matplotlib' 2>/dev/null || { [ -x /usr/bin/python3 ] && py=/usr/bin/python3; }
"$py" bench/plot_majorants.py bench/majorants.json bench/majorants.png
"$py" bench/plot_majorants.py bench/majorants.json --markdown
