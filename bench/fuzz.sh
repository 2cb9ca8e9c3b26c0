#!/usr/bin/env bash
# Fuzzes the BVH and ASF/AMC readers with cargo-fuzz (libFuzzer) and records
# executions and crashes in bench/results/fuzz.md.
#
# Usage: bench/fuzz.sh [SECONDS_PER_TARGET]   (default 600)
# Needs: a nightly toolchain (`rustup toolchain install nightly`) and
# `cargo install cargo-fuzz`. Seeds come from ../shared/data.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-600}
data=${MOCAP_SHARED_DATA:-../shared/data}

# Seed corpora: real files from other exporters, and short Bandai/HDM05 pieces.
mkdir -p fuzz/corpus/bvh fuzz/corpus/asf_amc
cp "$data"/parser-cases/*.bvh fuzz/corpus/bvh/
for f in "$data"/bandai/dataset-1/dataset-1_bow_normal_001.bvh; do
    head -c 20000 "$f" > fuzz/corpus/bvh/bandai_head.bvh   # truncated: exercises errors
    { sed -n '1,/^MOTION/p' "$f"; echo "Frames: 2"; echo "Frame Time: 0.0333333";
      sed -n '/^Frame Time/{n;p;n;p}' "$f"; } > fuzz/corpus/bvh/bandai_2frames.bvh
done
{ cat "$data"/hdm05-sample/HDM_bd.asf; printf '\0'; head -n 95 "$data"/hdm05-sample/HDM_bd_depositFloorR_001_120.amc; } \
    > fuzz/corpus/asf_amc/hdm05_3frames

report=bench/results/fuzz.md
{
    echo "# Fuzzing the readers"
    echo
    echo "Made by \`bench/fuzz.sh $seconds\` on $(date -u +%F), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), $(nproc) cores,"
    echo "cargo-fuzz $(cargo fuzz --version 2>/dev/null | awk '{print $2}'), $(rustc +nightly --version)."
    echo "Seeds: the parser-case BVH files, a truncated and a 2-frame Bandai file, the HDM05 ASF with 3 AMC frames."
    echo
    echo "| target | seconds | executions | exec/s | corpus entries | crashes |"
    echo "| --- | ---: | ---: | ---: | ---: | ---: |"
} > "$report.tmp"
for target in bvh asf_amc; do
    log=fuzz/$target.log
    set +e
    cargo +nightly fuzz run "$target" "fuzz/corpus/$target" -- \
        -max_total_time="$seconds" -max_len=65536 -print_final_stats=1 > "$log" 2>&1
    status=$?
    set -e
    execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
    rate=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
    corpus=$(ls "fuzz/corpus/$target" | wc -l)
    crashes=$(ls fuzz/artifacts/$target 2>/dev/null | grep -c '^crash-' || true)
    echo "| $target | $seconds | $execs | $rate | $corpus | $crashes (exit $status) |" >> "$report.tmp"
done
echo >> "$report.tmp"
echo "Each crash input found is kept as a regression test in crates/mocap-core/tests/fuzz_regressions.rs." >> "$report.tmp"
mv "$report.tmp" "$report"
cat "$report"
