#!/bin/bash
# Spikes of the trunk (session 22; bench/results/clean.md, "Spikes of the trunk"): where spike finding loses
# against the oracle and which joints' spikes it misses (spike_attribution, 120 validation takes, about 3 min),
# the 116-take evaluation with the default finder (trunk joints judged by their subtree's jump alone; clean_eval
# --despike, about 5 min), the spike figures over six noise draws of the test takes (spike_draws, about 4 min), and
# curved bridges against the straight one (bridge_shape, 120 validation takes, about 5 min).
# Binaries: CARGO_TARGET_DIR=target-clean cargo build --profile test -p mocap-clean --examples
set -e
cd "$(dirname "$0")/../.."
BIN=./target-clean/debug/examples
DATA=../shared/data/bandai
OUT=bench/clean/trunk
mkdir -p $OUT
$BIN/spike_attribution $DATA 1000 > $OUT/attribution.md
$BIN/clean_eval --data $DATA --tune-takes 12 --no-filters --despike --spike-lengths 2,4,8,16,32,64 \
  --json $OUT/eval-despike.json --markdown $OUT/eval-despike.md
$BIN/spike_draws $DATA 7,8,9,10,11,12 > $OUT/draws.md
$BIN/bridge_shape $DATA 1000 > $OUT/bridges.md
