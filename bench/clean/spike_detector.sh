#!/bin/bash
# The learned spike detector (mocap_clean::spikes, experimental, none ships; bench/results/clean.md "A learned
# spike detector"): width 32, 2 levels, 32-frame windows, trained on spikes alone (no random noise, spikes on
# every window), 40 steps x 512 windows per epoch, stopped after epoch 26 (the weights kept are epoch 26's); then
# evaluated on the first 40 test takes with the filters, the shipped model and spike finding.
# Binaries: CARGO_TARGET_DIR=target-clean cargo build --profile test -p mocap-clean --examples
set -e
cd "$(dirname "$0")/../.."
BIN=./target-clean/debug/examples
DATA=../shared/data/bandai
OUT=bench/clean/spike-detector
mkdir -p $OUT
if [ "$1" != "--eval-only" ]; then
  $BIN/clean_train --data $DATA --spike-detector --width 32 --levels 2 --window 32 --max-sigma 0 --spike-probability 1 \
    --out $OUT/detector.safetensors --state $OUT/detector.state --plot $OUT/detector.png \
    --epochs 26 --steps 40 --batch 512 --seed 1 --json $OUT/detector-train.json
fi
$BIN/clean_eval --data $DATA --max-takes 40 --tune-takes 12 --despike --spike-lengths 16,32 \
  --spike-model "spike detector=$OUT/detector.safetensors" \
  --json $OUT/eval-40.json --markdown $OUT/eval-40.md
