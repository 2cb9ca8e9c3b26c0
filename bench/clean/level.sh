#!/bin/bash
# A noise level robust to spikes (session 23; bench/results/clean.md, "A noise level robust to spikes"): the
# shipped model with the take's level pooled over its segments (sessions 7-22) and as the median of its
# segments' levels (the default since session 23), over six noise draws of the 116 test takes, and on clean and
# slightly noisy takes (level_estimate, about 7 min); then the 116-take evaluation with spike finding and the
# new default (clean_eval --despike, about 5 min).
# Binaries: cargo build --profile test -p mocap-clean --examples (or CARGO_TARGET_DIR=target-clean, BIN below)
set -e
cd "$(dirname "$0")/../.."
BIN=${BIN:-./target/debug/examples}
DATA=../shared/data/bandai
OUT=bench/clean/level
mkdir -p $OUT
$BIN/level_estimate $DATA 7,8,9,10,11,12 > $OUT/draws.md
$BIN/clean_eval --data $DATA --tune-takes 12 --no-filters --despike --spike-lengths 2,4,8,16,32,64 \
  --json $OUT/eval-despike.json --markdown $OUT/eval-despike.md
