#!/bin/bash
# Capacity check: the representation comparison's budget (6D, derivative loss, 6 epochs x 20 steps x 512,
# seed 1) with a network twice as wide (width 64), evaluated on the first 40 test takes next to the
# width-32 run (bench/clean/representations/rot6d.safetensors).
set -e
cd "$(dirname "$0")/../.."
BIN=./target-clean/debug/examples
DATA=../shared/data/bandai
OUT=bench/clean/width
mkdir -p $OUT
$BIN/clean_train --data $DATA --width 64 --out $OUT/w64.safetensors --state $OUT/w64.state --plot $OUT/w64.png \
  --epochs 6 --steps 20 --batch 512 --seed 1 --loss derivative --json $OUT/w64-train.json
$BIN/clean_eval --data $DATA --max-takes 40 --no-default-model --no-filters --spike-lengths 4,16 \
  --model "width 32=bench/clean/representations/rot6d.safetensors" --model "width 64=$OUT/w64.safetensors" \
  --json $OUT/eval.json --markdown $OUT/eval.md
