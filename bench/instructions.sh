#!/usr/bin/env bash
# The before/after check in work alone (bench/run.sh's step 3, without its timed steps):
# bench/work_count.cpp compiled with one command against commit BEFORE's include/ and examples/
# and against AFTER's (default: the working tree's), each run under valgrind's callgrind, and a
# table of instructions per kernel, new / old, with the kernels' lookups and checksums (equal
# checksums: the same paths were sampled, so the ratio is the code's alone). The harness itself
# is the working tree's on both sides.
#
#   bench/instructions.sh [BEFORE [AFTER]]     (BEFORE default: HEAD; needs valgrind)
#
# The instruction count is deterministic for a given binary and input, so one run suffices on a
# noisy machine. The whole run takes about four minutes on 2 cores (two compiles, two runs under
# callgrind). Output: the table on stdout; the raw files in ${NSP_INSTRUCTIONS_DIR:-build-instructions}.
set -euo pipefail
cd "$(dirname "$0")/.."
before=${1:-HEAD}
after=${2:-}
want=$(git rev-parse --verify "$before^{commit}")
command -v valgrind >/dev/null || { echo "instructions.sh: valgrind is needed (apt-get install valgrind)" >&2; exit 2; }
out=${NSP_INSTRUCTIONS_DIR:-build-instructions}
mkdir -p "$out"
source bench/work_count.sh  # work_cc, count_instructions

src=$(cd "$out" && pwd)/before-src
new_src=.
trees=("$src")
if [ -n "$after" ]; then
    new_src=$(cd "$out" && pwd)/after-src
    trees+=("$new_src")
fi
cleanup() { for t in "${trees[@]}"; do git worktree remove --force "$t" 2>/dev/null || true; done; }
cleanup
git worktree prune
git worktree add --detach "$src" "$want" >/dev/null
[ -z "$after" ] || git worktree add --detach "$new_src" "$(git rev-parse --verify "$after^{commit}")" >/dev/null
trap cleanup EXIT
echo "instructions.sh: compiling bench/work_count.cpp against $(git rev-parse --short "$want") and ${after:-the working tree}" >&2
work_cc "$src" "$out/work-old" &
work_cc "$new_src" "$out/work-new" &
wait %1 && wait %2
cleanup
trap - EXIT

for side in old new; do
    echo "instructions.sh: running the $side build under callgrind" >&2
    count_instructions "$out/work-$side" "$out" "$side"
done

python3 - "$out" "$(git rev-parse --short "$want")" "${after:-the working tree}" <<'EOF'
import sys
out, before, after = sys.argv[1], sys.argv[2], sys.argv[3]
def load(side):
    ir = {}
    for line in open(f"{out}/ir-{side}.txt"):
        name, n = line.split()[0], int(line.split()[-1])
        ir[name] = n
    work = {}
    for line in open(f"{out}/work-{side}.txt"):
        name, calls, lookups, checksum = line.split()
        work[name] = (int(calls), int(lookups), checksum)
    return ir, work
ir_old, w_old = load("old")
ir_new, w_new = load("new")
print(f"Instructions per kernel: {after} against {before} (callgrind; new / old)\n")
print(f"| kernel | calls | instructions old | instructions new | new / old | lookups | same paths |")
print(f"|---|---|---|---|---|---|---|")
for name in w_new:
    if name not in w_old or name not in ir_old or name not in ir_new:
        print(f"| {name} | {w_new[name][0]} | - | {ir_new.get(name, '-')} | - | {w_new[name][1]} | new kernel |")
        continue
    same = "yes" if w_old[name][1:] == w_new[name][1:] else f"no (lookups {w_old[name][1]} -> {w_new[name][1]})"
    print(f"| {name} | {w_new[name][0]} | {ir_old[name]} | {ir_new[name]} | {ir_new[name] / ir_old[name]:.4f} | "
          f"{w_new[name][1]} | {same} |")
EOF
