#!/bin/bash
# The network corrects a Butterworth filter's output instead of its input (TrainOptions::base_filter,
# bench/results/clean.md "A network on top of the filter"). The shipped model's first stage (width 64,
# derivative loss, 40 steps x 512 windows per epoch, lr 1e-3, seed 1, default noise) for 12 epochs,
# evaluated on the first 40 test takes with the tuned filters and the shipped model. With --window32: the same
# with 32-frame windows and 256 windows per batch (the same frames per step).
# Binaries: CARGO_TARGET_DIR=target-clean cargo build --profile test -p mocap-clean --examples
set -e
cd "$(dirname "$0")/../.."
BIN=./target-clean/debug/examples
DATA=../shared/data/bandai
OUT=bench/clean/base-filter
mkdir -p $OUT
if [ "$1" == "--window32" ]; then
  $BIN/clean_train --data $DATA --width 64 --window 32 --base-filter butterworth:2:2 --out $OUT/butterworth-base-w32.safetensors \
    --state $OUT/butterworth-base-w32.state --plot $OUT/butterworth-base-w32.png --epochs 12 --steps 40 --batch 256 --seed 1 \
    --loss derivative --json $OUT/butterworth-base-w32-train.json
  $BIN/clean_eval --data $DATA --max-takes 40 --tune-takes 12 --spike-lengths 4,16 \
    --model "butterworth base, 12 epochs=$OUT/butterworth-base.safetensors" \
    --model "butterworth base, window 32=$OUT/butterworth-base-w32.safetensors" \
    --json $OUT/eval-w32.json --markdown $OUT/eval-w32.md
  exit 0
fi
if [ "$1" != "--eval-only" ]; then
  $BIN/clean_train --data $DATA --width 64 --base-filter butterworth:2:2 --out $OUT/butterworth-base.safetensors \
    --state $OUT/butterworth-base.state --plot $OUT/butterworth-base.png --epochs 12 --steps 40 --batch 512 --seed 1 \
    --loss derivative --json $OUT/butterworth-base-train.json
fi
$BIN/clean_eval --data $DATA --max-takes 40 --tune-takes 12 --spike-lengths 4,16 \
  --model "butterworth base, 12 epochs=$OUT/butterworth-base.safetensors" \
  --json $OUT/eval.json --markdown $OUT/eval.md
