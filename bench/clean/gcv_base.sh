#!/bin/bash
# The network on top of the cross-validated Butterworth (bench/results/clean.md, "The network on top of the
# cross-validated Butterworth"): the shipped model's recipe (width 64, 32-frame windows, derivative loss,
# 12 epochs x 40 steps x 256 windows, lr 1e-3, seed 1, default noise) with --base-filter butterworth-gcv:2 and
# --base-context 128 (noise and filter on the window plus up to 128 frames of its take on each side; in use the
# filter runs over the whole take). Then the 116-take evaluation with the tuned filters, the shipped model and it.
# With --window64: 64-frame windows; with --finetune: four more epochs at lr 1e-4 (below); with --despike: the shipped and the previous model with spike finding. The variant that also fed the filter's output to the network
# (--base-as-guide, `bench/clean/gcv_base.sh --guide` at commit 7ee92bb) measured the same and was removed.
# Binaries: CARGO_TARGET_DIR=target-clean cargo build --profile test -p mocap-clean --examples
set -e
cd "$(dirname "$0")/../.."
BIN=./target-clean/debug/examples
DATA=../shared/data/bandai
OUT=bench/clean/gcv-base
mkdir -p $OUT
if [ "$1" == "--window64" ]; then
  # The same with 64-frame windows and 128 per batch (the same frames per step).
  $BIN/clean_train --data $DATA --width 64 --window 64 --base-filter butterworth-gcv:2 --base-context 128 \
    --out $OUT/gcv-base-w64.safetensors --state $OUT/gcv-base-w64.state --plot $OUT/gcv-base-w64.png \
    --epochs 12 --steps 40 --batch 128 --seed 1 --loss derivative --json $OUT/gcv-base-w64-train.json
  $BIN/clean_eval --data $DATA --tune-takes 12 --spike-lengths 2,4,8,16,32,64 \
    --model "gcv base, context 128, window 64=$OUT/gcv-base-w64.safetensors" \
    --json $OUT/eval-w64.json --markdown $OUT/eval-w64.md
  exit 0
fi
if [ "$1" == "--finetune" ]; then
  # Four more epochs of the trained model at lr 1e-4 (its validation MSE was flat at lr 1e-3 from epoch 6).
  if [ ! -d $OUT/gcv-base-ft.state ]; then cp -r $OUT/gcv-base.state $OUT/gcv-base-ft.state; fi
  $BIN/clean_train --data $DATA --width 64 --window 32 --base-filter butterworth-gcv:2 --base-context 128 \
    --out $OUT/gcv-base-ft.safetensors --state $OUT/gcv-base-ft.state --plot $OUT/gcv-base-ft.png --resume \
    --epochs 16 --steps 40 --batch 256 --lr 1e-4 --seed 1 --loss derivative --json $OUT/gcv-base-ft-train.json
  $BIN/clean_eval --data $DATA --tune-takes 12 --spike-lengths 2,4,8,16,32,64 \
    --model "gcv base, context 128=$OUT/gcv-base.safetensors" \
    --model "gcv base, context 128, +4 epochs at lr 1e-4=$OUT/gcv-base-ft.safetensors" \
    --json $OUT/eval-ft.json --markdown $OUT/eval-ft.md
  exit 0
fi
if [ "$1" == "--despike" ]; then
  # The shipped model (this one, since session 6) and the one shipped before it, each also followed by spike finding.
  PREVIOUS=$OUT/previous-default.safetensors
  if [ ! -f $PREVIOUS ]; then git show 1ac5da5:models/clean-default.safetensors > $PREVIOUS; fi
  $BIN/clean_eval --data $DATA --tune-takes 12 --despike --spike-lengths 2,4,8,16,32,64 \
    --model "previous shipped model (network on the per-window 2 Hz Butterworth)=$PREVIOUS" \
    --json $OUT/eval-despike.json --markdown $OUT/eval-despike.md
  exit 0
fi
if [ "$1" != "--eval-only" ]; then
  $BIN/clean_train --data $DATA --width 64 --window 32 --base-filter butterworth-gcv:2 --base-context 128 \
    --out $OUT/gcv-base.safetensors --state $OUT/gcv-base.state --plot $OUT/gcv-base.png \
    --epochs 12 --steps 40 --batch 256 --seed 1 --loss derivative --json $OUT/gcv-base-train.json
fi
$BIN/clean_eval --data $DATA --tune-takes 12 --spike-lengths 2,4,8,16,32,64 \
  --model "gcv base, context 128=$OUT/gcv-base.safetensors" \
  --json $OUT/eval.json --markdown $OUT/eval.md
