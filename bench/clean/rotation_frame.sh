#!/bin/bash
# Local rotations against rotations relative to the pelvis (bench/results/clean.md, "Rotations relative to
# the pelvis"), on the random noise without error on the helper root. The representation comparison's
# budget (6D, small network, derivative loss, 6 epochs x 20 steps x 512 windows, seed 1, same training
# takes and noise stream) for each frame, then the `clean_eval` example on the first 40 test takes.
# (bench/clean/frame/old-noise holds the first pelvis run, on the noise with the helper root perturbed.)
# Binaries: CARGO_TARGET_DIR=target-clean cargo build --profile test -p mocap-clean --examples
set -e
cd "$(dirname "$0")/../.."
BIN=./target-clean/debug/examples
DATA=../shared/data/bandai
OUT=bench/clean/frame
mkdir -p $OUT
if [ "$1" != "--eval-only" ]; then
  for frame in local pelvis; do
    $BIN/clean_train --data $DATA --rotations $frame --out $OUT/$frame.safetensors --state $OUT/$frame.state \
      --plot $OUT/$frame.png --epochs 6 --steps 20 --batch 512 --seed 1 --loss derivative --json $OUT/$frame-train.json
  done
fi
$BIN/clean_eval --data $DATA --max-takes 40 --no-default-model --no-filters --spike-lengths 4,16 \
  --model "local=$OUT/local.safetensors" --model "pelvis=$OUT/pelvis.safetensors" \
  --json $OUT/eval.json --markdown $OUT/eval.md
