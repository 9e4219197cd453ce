#!/usr/bin/env bash
# Builds nsp_bench (Release) and runs, in one command:
#   1. every benchmark, with repetitions in random interleaved order (medians, lookup-rate
#      ratios, spectral estimators, the cost of each spectral mode on the grey cloud);
#   2. the before/after Mono check in time: every Mono benchmark under the global majorant (raw
#      lookups, trackers, grey path estimators), run by this binary and by the binary of commit
#      $NSP_BENCH_BEFORE (built once from a temporary git worktree, which is
#      removed again) back to back, in several rounds (median of the paired ratios);
#   3. the same check in work: bench/work_count.cpp built against both versions of include/,
#      instructions per kernel under valgrind's callgrind (noise-free), lookups and checksums;
# then prints the tables (bench/report.py; --markdown gives them as Markdown).
#
# Build directory: $NSP_BENCH_BUILD if set; else ./build if scripts/setup.sh configured it (a
# Release build with benchmarks at -O3); else ./build-bench, configured here. Environment:
#   NSP_BENCH_REPS        repetitions of every benchmark in step 1 (default 5)
#   NSP_BENCH_JOBS        build parallelism (default: nproc)
#   NSP_BENCH_BEFORE      the "before" commit of steps 2 and 3 (default 08dc9b7, the commit before
#                         the majorant axis: |mu_n| event probabilities, bound-policy branches and
#                         the DDA-step report in free_flight; d0f6439 was the commit before the
#                         chromatic work); empty skips steps 2 and 3
#   NSP_BENCH_BEFORE_BUILD where to build it (default <build>-before; kept, keyed by commit)
#   NSP_BENCH_AB_ROUNDS   rounds of step 2 (default 6): pairs per benchmark
#   CXX                   compiler of step 3 (default c++)
# Extra arguments go to nsp_bench in step 1 (e.g. --benchmark_filter=Track).
# Results: <build>/bench/results.json; <build>/bench/ab/: {old,new}-<round>-<i>.json (step 2),
# work-{old,new}.txt and ir-{old,new}.txt (step 3).
# The whole run takes about nine minutes on 2 cores (step 1 ~3.5 min, step 2 ~4.5 min, step 3 under
# 1 min), plus the one-time build of the old commit.
set -euo pipefail
cd "$(dirname "$0")/.."

is_release_with_benchmarks() {  # at the build type's -O3: not run-main.sh's -O1 build
    [ -f "$1/CMakeCache.txt" ] && grep -q '^NSP_BUILD_BENCHMARKS:BOOL=ON' "$1/CMakeCache.txt" &&
        grep -q '^CMAKE_BUILD_TYPE:STRING=Release' "$1/CMakeCache.txt" &&
        ! grep -q '^NSP_OPTIMIZE:STRING=.' "$1/CMakeCache.txt"
}

generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
jobs=${NSP_BENCH_JOBS:-$(nproc)}

build=${NSP_BENCH_BUILD:-}
if [ -z "$build" ]; then
    build=build-bench
    is_release_with_benchmarks build && build=build
fi
if ! is_release_with_benchmarks "$build"; then
    cmake -S . -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DNSP_BUILD_BENCHMARKS=ON \
          -DNSP_BUILD_TESTS=OFF -DNSP_BUILD_EXAMPLES=OFF >/dev/null
fi
cmake --build "$build" --target nsp_bench --parallel "$jobs"

# What was measured: the commit, and which of the measured directories differ from it.
code=unknown
if git rev-parse --git-dir >/dev/null 2>&1; then
    code=$(git rev-parse --short HEAD)
    for d in include examples bench; do
        [ -z "$(git status --porcelain -- "$d")" ] || code="$code+local-$d"
    done
    case $code in *+local-*)
        echo "note: measuring the working tree, which differs from HEAD ($code)" >&2 ;;
    esac
fi

# Step 1: every benchmark.
json=$build/bench/results.json
"$build/bench/nsp_bench" --benchmark_repetitions="${NSP_BENCH_REPS:-5}" \
    --benchmark_enable_random_interleaving=true \
    --benchmark_report_aggregates_only=true \
    --benchmark_context=code="$code" \
    --benchmark_out="$json" --benchmark_out_format=json "$@"

# Steps 2 and 3: the before/after Mono check, against the binary of commit $NSP_BENCH_BEFORE.
before=${NSP_BENCH_BEFORE-08dc9b7}
ab=
if [ -n "$before" ]; then
    if ! want=$(git rev-parse --verify --quiet "$before^{commit}"); then
        echo "note: commit $before is not available here; skipping the before/after check" >&2
    else
        source bench/work_count.sh  # work_cc, count_instructions
        old_build=${NSP_BENCH_BEFORE_BUILD:-$build-before}
        old_bin=$old_build/build/bench/nsp_bench
        if [ ! -x "$old_bin" ] || [ ! -x "$old_build/work_count" ] || [ "$(cat "$old_build/commit" 2>/dev/null)" != "$want" ]; then
            # A temporary worktree of the old commit: built, then removed (the binaries stay).
            mkdir -p "$old_build"
            src=$(cd "$old_build" && pwd)/src
            git worktree remove --force "$src" 2>/dev/null || true  # left by an interrupted run
            git worktree prune
            git worktree add --detach "$src" "$want" >/dev/null
            trap 'git worktree remove --force "$src"' EXIT
            cmake -S "$src" -B "$old_build/build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
                  -DNSP_BUILD_BENCHMARKS=ON -DNSP_BUILD_TESTS=OFF -DNSP_BUILD_EXAMPLES=OFF >/dev/null
            cmake --build "$old_build/build" --target nsp_bench --parallel "$jobs"
            work_cc "$src" "$old_build/work_count"
            git worktree remove --force "$src"
            trap - EXIT
            echo "$want" >"$old_build/commit"
        fi
        ab=$build/bench/ab
        rm -rf "$ab"
        mkdir -p "$ab"

        # Step 2: time. Every Mono benchmark under the global majorant (raw lookups, trackers, path
        # estimators; not the grid-majorant trackers, which the old binary lacks), one repetition at a time in pairs: old and new binary back to back on the
        # same benchmark (which goes first alternates), benchmarks in a new random order each
        # round. A pair is measured within about a second, so a change in the machine's load
        # between the two sides is rare; report.py takes the median of the pair ratios.
        filter='^(BM_RawLookup(Chained)?<Mono.*|BM_Track<[A-Za-z]+, Mono(, (Cloud|Trivial)(, [A-Za-z]+)?)?>(/.*)?|BM_Radiance/.*/mono/.*)$'
        mapfile -t names < <("$build/bench/nsp_bench" --benchmark_list_tests --benchmark_filter="$filter")
        rounds=${NSP_BENCH_AB_ROUNDS:-6}
        for r in $(seq 1 "$rounds"); do
            echo "before/after round $r/$rounds: ${#names[@]} benchmarks, each on both binaries" >&2
            i=0
            while IFS= read -r name; do
                i=$((i + 1))
                # The exact name as a regex: escape the metacharacters it may hold.
                pattern="^$(printf '%s' "$name" | sed 's/[][\.*^$+?(){}|]/\\&/g')\$"
                if [ $(((r + i) % 2)) = 0 ]; then order="old new"; else order="new old"; fi
                for side in $order; do
                    bin=$build/bench/nsp_bench
                    [ "$side" = old ] && bin=$old_bin
                    "$bin" --benchmark_filter="$pattern" --benchmark_out="$ab/$side-$r-$i.json" \
                        --benchmark_out_format=json >/dev/null 2>&1 || echo "note: $side binary failed on $name" >&2
                done
            done < <(printf '%s\n' "${names[@]}" | shuf)
        done

        # Step 3: work. bench/work_count.cpp built against both include/ trees with one command,
        # run under callgrind: instructions per kernel (deterministic), lookups and checksums.
        work_cc . "$build/bench/work_count"
        if command -v valgrind >/dev/null; then
            for side in old new; do
                bin=$build/bench/work_count
                [ "$side" = old ] && bin=$old_build/work_count
                echo "instruction count: $side build (callgrind)" >&2
                count_instructions "$bin" "$ab" "$side"
            done
        else
            echo "note: valgrind not found; skipping the instruction count" >&2
            "$build/bench/work_count" >"$ab/work-new.txt"
            "$old_build/work_count" >"$ab/work-old.txt"
        fi
    fi
fi

echo
python3 bench/report.py "$json" ${ab:+--ab "$ab"}
