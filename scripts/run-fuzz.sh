#!/usr/bin/env bash
# Builds the libFuzzer target nsp_fuzz_kernels (tests/fuzz, issue 8) with clang into ./build-fuzz
# and runs it, one process, for NSP_FUZZ_SECONDS (default 120) over a scratch copy of
# tests/fuzz/corpus, so a CI run leaves the checkout clean. Any crash (a broken invariant, a
# sanitizer report, a timeout) fails the run; the input is left in the scratch directory's
# artifacts/ and printed in base64. Installs clang and libclang-rt-dev if missing (root or sudo).
# usage: scripts/run-fuzz.sh                  fuzz for NSP_FUZZ_SECONDS
#        scripts/run-fuzz.sh --update-corpus  fuzz, then merge what it found into tests/fuzz/corpus
#                                             (-merge=1 keeps only inputs that add coverage)
set -euo pipefail
cd "$(dirname "$0")/.."
repo="$(pwd)"

update=0
case "${1:-}" in
    "") ;;
    --update-corpus) update=1 ;;
    *) echo "usage: $0 [--update-corpus]" >&2; exit 2 ;;
esac
seconds="${NSP_FUZZ_SECONDS:-120}"
runs="${NSP_FUZZ_RUNS:-30000}"
[ "$runs" != 0 ] || runs=-1  # libFuzzer: -runs=-1 is unlimited

scripts/install-packages.sh run-fuzz cmake ninja-build clang libclang-rt-dev libglm-dev libeigen3-dev

generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
CC=clang CXX=clang++ cmake -S . -B build-fuzz "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
    -DNSP_BUILD_FUZZER=ON -DNSP_BUILD_TESTS=OFF -DNSP_BUILD_EXAMPLES=OFF -DNSP_BUILD_BENCHMARKS=OFF
cmake --build build-fuzz --parallel "${NSP_FUZZ_BUILD_JOBS:-$(nproc)}" --target nsp_fuzz_kernels

scratch="$(mktemp -d "${TMPDIR:-/tmp}/nsp-fuzz.XXXXXX")"
mkdir -p "$scratch/corpus" "$scratch/artifacts"
cp tests/fuzz/corpus/* "$scratch/corpus/"
echo "run-fuzz: ${seconds} s over a copy of tests/fuzz/corpus in $scratch"
# -max_len bounds the structure and the random numbers an input may carry; -timeout (s) catches an
# input whose work the harness failed to bound; -rss_limit_mb a runaway allocation.
status=0
# -seed and -runs fix what a run explores (NSP_FUZZ_SEED, default 1; NSP_FUZZ_RUNS, default 30000
# inputs, about a minute here; 0 = no limit, only NSP_FUZZ_SECONDS): CI runs the same sequence every
# time, so a red run is reproducible, not luck. To look for new inputs, fuzz locally with other
# seeds, NSP_FUZZ_RUNS=0 and a longer NSP_FUZZ_SECONDS, then --update-corpus.
(cd "$scratch" && "$repo/build-fuzz/tests/fuzz/nsp_fuzz_kernels" -max_len=1024 -timeout=10 -rss_limit_mb=2048 \
    -seed="${NSP_FUZZ_SEED:-1}" -runs="$runs" -max_total_time="$seconds" -print_final_stats=1 -artifact_prefix="$scratch/artifacts/" corpus) || status=$?
if [ "$status" -ne 0 ] || [ -n "$(ls -A "$scratch/artifacts")" ]; then
    echo "run-fuzz: FAILED (exit $status); inputs in $scratch/artifacts:" >&2
    for f in "$scratch"/artifacts/*; do
        [ -e "$f" ] && echo "  $f  base64: $(base64 -w0 "$f")" >&2
    done
    exit 1
fi

if [ "$update" -eq 1 ]; then
    # Re-minimise: merge the checked-in corpus and what this run found into an empty directory
    # (-merge=1 keeps an input only if it adds coverage, smallest first; -use_counters=0 counts
    # edges, not hit counts, which keeps about a third as many), then replace the corpus with it.
    # Inputs of findings (finding-*) are kept as they are, whatever their coverage.
    mkdir -p "$scratch/merged"
    (cd "$scratch" && "$repo/build-fuzz/tests/fuzz/nsp_fuzz_kernels" -merge=1 -use_counters=0 -max_len=1024 -timeout=10 \
        merged "$repo/tests/fuzz/corpus" corpus)
    find tests/fuzz/corpus -type f ! -name 'finding-*' -delete
    cp "$scratch"/merged/* tests/fuzz/corpus/ 2>/dev/null || true
    n=$(ls tests/fuzz/corpus | wc -l)
    kb=$(du -sk tests/fuzz/corpus | cut -f1)
    echo "run-fuzz: tests/fuzz/corpus now holds $n files, ${kb} KB"
    if [ "$n" -ge 300 ] || [ "$kb" -ge 200 ]; then
        echo "run-fuzz: the corpus outgrew 300 files / 200 KB: keep its largest ~290 files and merge them" \
             "again into an empty directory (how 4eb4b71 chose it)" >&2
    fi
fi
rm -rf "$scratch"
echo "run-fuzz: OK"
