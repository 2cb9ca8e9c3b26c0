#!/bin/bash
# Does training on spikes cost the model its random-noise quality? The shipped model's first stage
# (width 64, derivative loss, 40 steps x 512 windows per epoch at lr 1e-3, seed 1) for 12 epochs with and
# without spikes in the training windows, evaluated on the first 40 test takes with the tuned filters.
# Binaries: CARGO_TARGET_DIR=target-clean cargo build --profile test -p mocap-clean --examples
set -e
cd "$(dirname "$0")/../.."
BIN=./target-clean/debug/examples
DATA=../shared/data/bandai
OUT=bench/clean/no-spikes
mkdir -p $OUT
if [ "$1" != "--eval-only" ]; then
  $BIN/clean_train --data $DATA --width 64 --spike-probability 0 --out $OUT/random-only.safetensors \
    --state $OUT/random-only.state --plot $OUT/random-only.png --epochs 12 --steps 40 --batch 512 --seed 1 \
    --loss derivative --json $OUT/random-only-train.json
fi
$BIN/clean_eval --data $DATA --max-takes 40 --tune-takes 12 --spike-lengths 4,16 \
  --model "random noise only, 12 epochs=$OUT/random-only.safetensors" \
  --json $OUT/eval.json --markdown $OUT/eval.md
