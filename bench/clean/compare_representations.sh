#!/bin/bash
# Trained comparison of rotation representations (bench/results/clean.md, "Rotation representations").
# Equal budget for each: the loss comparison's setting (small network, 6 epochs x 20 steps x 512 windows,
# derivative loss, seed 1, same training takes and noise stream), then the `clean_eval` example on the
# first 40 test takes, both noise conditions, no filters (they do not depend on the representation).
# Binaries: CARGO_TARGET_DIR=target-clean cargo build --profile test -p mocap-clean --examples
set -e
cd "$(dirname "$0")/../.."
BIN=./target-clean/debug/examples
DATA=../shared/data/bandai
OUT=bench/clean/representations
mkdir -p $OUT
if [ "$1" != "--eval-only" ]; then
  for r in rot6d expmap euler; do
    $BIN/clean_train --data $DATA --representation $r --out $OUT/$r.safetensors --state $OUT/$r.state \
      --plot $OUT/$r.png --epochs 6 --steps 20 --batch 512 --seed 1 --loss derivative --json $OUT/$r-train.json
  done
fi
$BIN/clean_eval --data $DATA --max-takes 40 --no-default-model --no-filters --spike-lengths 4,16 \
  --model "rot6d=$OUT/rot6d.safetensors" --model "expmap=$OUT/expmap.safetensors" \
  --model "euler=$OUT/euler.safetensors" --json $OUT/eval.json --markdown $OUT/eval.md
