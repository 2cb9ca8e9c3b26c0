#!/bin/bash
# Spike finding on global rotations, in the take as captured, before the model (session 9; bench/results/clean.md,
# "Spike finding on global rotations"): which statistic tells a spike's boundary from IK noise (spike_boundaries, 40
# validation takes, seconds), which settings and where to look (spike_finding, all validation takes, about 7 min),
# what the oracle study says now (spike_oracle.sh), and the 116-take evaluation with spike finding tuned on the
# validation takes (clean_eval --despike, about 10 min).
# Binaries: CARGO_TARGET_DIR=target-clean cargo build --profile test -p mocap-clean --examples
set -e
cd "$(dirname "$0")/../.."
BIN=./target-clean/debug/examples
DATA=../shared/data/bandai
OUT=bench/clean/spikes
mkdir -p $OUT
$BIN/spike_boundaries $DATA 40 > $OUT/boundaries.md
$BIN/spike_finding $DATA 1000 > $OUT/finding.md
bash bench/clean/spike_oracle.sh
$BIN/clean_eval --data $DATA --tune-takes 1000 --no-filters --despike --spike-lengths 2,4,8,16,32,64 \
  --json $OUT/eval-despike.json --markdown $OUT/eval-despike.md
