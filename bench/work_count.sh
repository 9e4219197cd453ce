# bench/work_count.sh: sourced by bench/run.sh (step 3) and bench/instructions.sh, so both count
# instructions the same way.

# work_cc TREE OUT: bench/work_count.cpp (the working tree's harness) compiled against TREE's
# include/ and examples/ with CMake's Release flags, one command for both sides of a comparison.
work_cc() {
    "${CXX:-c++}" -O3 -DNDEBUG -std=gnu++20 -I"$1/examples" -I"$1/include" -isystem /usr/include/eigen3 \
        bench/work_count.cpp -o "$2"
}

# count_instructions BIN DIR SIDE: runs BIN under valgrind's callgrind. Writes DIR/work-SIDE.txt
# (its lookups and checksums), DIR/valgrind-SIDE.log and DIR/ir-SIDE.txt, one line per kernel:
# "<kernel> <instructions>" (work_count dumps once per kernel).
count_instructions() {
    local bin=$1 dir=$2 side=$3 f
    rm -f "$dir/cg-$side" "$dir/cg-$side".*
    valgrind --tool=callgrind --instr-atstart=no --callgrind-out-file="$dir/cg-$side" "$bin" \
        >"$dir/work-$side.txt" 2>"$dir/valgrind-$side.log"
    for f in "$dir/cg-$side".*; do
        sed -n -e 's/^desc: Trigger: Client Request: //p' -e 's/^summary: //p' "$f" | paste -sd' '
    done >"$dir/ir-$side.txt"
    rm -f "$dir/cg-$side" "$dir/cg-$side".*
}
