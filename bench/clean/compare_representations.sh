#!/bin/bash
# Trained comparison of rotation representations (bench/results/clean.md, "Rotation representations").
# Equal budget for each: the loss comparison's setting (small network, 6 epochs x 20 steps x 512 windows by default,
# derivative loss, seed 1, same training takes and noise stream), then the `clean_eval` example on the
# first 40 test takes, both noise conditions, no filters (they do not depend on the representation).
# Binaries: CARGO_TARGET_DIR=target-clean cargo build --profile test -p mocap-clean --examples
# (or BIN=another build's examples folder). OUT: where the models and results go (default
# bench/clean/representations, the sessions 1-2 run on the earlier noise; session 17's run on the
# corrected noise: OUT=bench/clean/representations-corrected).
set -e
cd "$(dirname "$0")/../.."
BIN=${BIN:-./target-clean/debug/examples}
DATA=../shared/data/bandai
OUT=${OUT:-bench/clean/representations}
# Training budget per representation (sessions 1-2: 6 x 20; session 17: EPOCHS=20 STEPS=40, the budget of
# the loss comparison on the corrected noise, since 6 x 20 leaves the networks undertrained there).
EPOCHS=${EPOCHS:-6}
STEPS=${STEPS:-20}
mkdir -p $OUT
if [ "$1" != "--eval-only" ]; then
  for r in rot6d expmap euler; do
    $BIN/clean_train --data $DATA --representation $r --out $OUT/$r.safetensors --state $OUT/$r.state \
      --plot $OUT/$r.png --epochs $EPOCHS --steps $STEPS --batch 512 --seed 1 --loss derivative --json $OUT/$r-train.json
  done
fi
$BIN/clean_eval --data $DATA --max-takes 40 --no-default-model --no-filters --spike-lengths 4,16 \
  --model "rot6d=$OUT/rot6d.safetensors" --model "expmap=$OUT/expmap.safetensors" \
  --model "euler=$OUT/euler.safetensors" --json $OUT/eval.json --markdown $OUT/eval.md
