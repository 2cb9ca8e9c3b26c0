#!/usr/bin/env bash
# Fuzzes what reads untrusted bytes (files, model files, datagrams, HTTP
# requests) with cargo-fuzz (libFuzzer) and records executions and crashes in
# bench/results/fuzz.md.
#
# Usage: bench/fuzz.sh [SECONDS_PER_TARGET [TARGET...]]   (default 600, all targets)
# Each target's latest run is kept as a row in bench/results/fuzz-rows/TARGET.md
# and the report is assembled from all rows.
# Needs: a nightly toolchain (`rustup toolchain install nightly`) and
# `cargo install cargo-fuzz`. Seeds come from ../shared/data.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-600}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=($(sed -n 's/^name = "\(.*\)"$/\1/p' fuzz/Cargo.toml | grep -v mocap-fuzz))
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
# The shipped style model and Wiener filter (the denoiser, 20 MB, is too
# slow to load a thousand times a second).
mkdir -p fuzz/corpus/model_file
cp models/style-default.safetensors models/clean-wiener.safetensors fuzz/corpus/model_file/
# Small inputs committed beside the targets (requests, datagrams, NTU files).
for dir in fuzz/seeds/*/; do
    target=$(basename "$dir")
    mkdir -p "fuzz/corpus/$target"
    cp "$dir"* "fuzz/corpus/$target/"
done

report=bench/results/fuzz.md
rows=bench/results/fuzz-rows
mkdir -p "$rows"
for target in "${targets[@]}"; do
    log=fuzz/$target.log
    rm -f fuzz/artifacts/$target/crash-*
    set +e
    max_len=65536
    [ "$target" = model_file ] && max_len=4194304
    cargo +nightly fuzz run "$target" "fuzz/corpus/$target" -- \
        -max_total_time="$seconds" -max_len=$max_len -print_final_stats=1 > "$log" 2>&1
    status=$?
    set -e
    execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
    rate=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
    corpus=$(ls "fuzz/corpus/$target" | wc -l)
    crashes=$(ls fuzz/artifacts/$target 2>/dev/null | grep -c '^crash-' || true)
    echo "| $target | $(date -u +%F) | $seconds | $execs | $rate | $corpus | $crashes (exit $status) |" > "$rows/$target.md"
done
{
    echo "# Fuzzing what reads untrusted bytes"
    echo
    echo "Made by \`bench/fuzz.sh SECONDS [TARGET...]\` (libFuzzer via cargo-fuzz $(cargo fuzz --version 2>/dev/null | awk '{print $2}'), $(rustc +nightly --version)),"
    echo "on $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), $(nproc) cores, shared with other builds (exec/s is therefore low)."
    echo
    echo "| target | what it feeds | seeds |"
    echo "| --- | --- | --- |"
    echo "| bvh | the BVH reader; what it reads must write back and read again to the same motion | parser-case files, a truncated and a 2-frame Bandai take |"
    echo "| asf_amc | the ASF and AMC readers (input split at the first NUL) | the HDM05 ASF with 3 AMC frames |"
    echo "| model_file | the denoiser, Wiener filter and style model loaders, each input as it is and resealed (checksum recomputed) | the shipped style model and Wiener filter |"
    echo "| viewer_request | one connection to the web viewer's HTTP server, on a paused clock | fuzz/seeds/viewer_request |"
    echo "| fuse_datagram | datagrams decoded and pushed through the fusion server's timeline | fuzz/seeds/fuse_datagram |"
    echo "| ntu_skeleton | the NTU RGB+D .skeleton reader | fuzz/seeds/ntu_skeleton |"
    echo
    echo "| target | date | seconds | executions | exec/s | corpus entries | crashes |"
    echo "| --- | --- | ---: | ---: | ---: | ---: | ---: |"
    cat "$rows"/*.md
    echo
    echo "model_file is slow by nature: each input is a whole model file (the seeds are 1 and 2.4 MB), loaded"
    echo "twice, so ten minutes try about two thousand files against millions of datagrams or requests."
    echo "Two targets ran at once, one per core."
    echo
    echo "Crashes these targets found, each kept as a regression test in crates/mocap-core/tests/fuzz_regressions.rs:"
    echo
    echo "- bvh (after 146,038 executions): a JOINT name holding NUL and CR bytes could be read but not written"
    echo "  back. The reader refuses control characters in joint names with a located error."
} > "$report.tmp"
mv "$report.tmp" "$report"
cat "$report"
