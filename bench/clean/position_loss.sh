#!/bin/bash
# The position (forward-kinematics) term of the loss: the representation comparison's budget
# (small network, 6D, derivative loss, 6 epochs x 20 steps x 512, seed 1) with position weights W
# (per cm^2), evaluated like the representations (first 40 test takes, no filters) next to the
# rot6d run without the position term (bench/clean/representations/rot6d.safetensors).
# Usage: bench/clean/position_loss.sh [W ...]   (default: 0.01 0.1)
set -e
cd "$(dirname "$0")/../.."
BIN=./target-clean/debug/examples
DATA=../shared/data/bandai
OUT=bench/clean/position
mkdir -p $OUT
WEIGHTS=${@:-0.01 0.1}
MODELS=(--model "no position term=bench/clean/representations/rot6d.safetensors")
for w in $WEIGHTS; do
  if [ ! -f $OUT/w$w.safetensors ]; then
    $BIN/clean_train --data $DATA --position-weight $w --out $OUT/w$w.safetensors --state $OUT/w$w.state \
      --plot $OUT/w$w.png --epochs 6 --steps 20 --batch 512 --seed 1 --loss derivative --json $OUT/w$w-train.json
  fi
  MODELS+=(--model "position weight $w=$OUT/w$w.safetensors")
done
$BIN/clean_eval --data $DATA --max-takes 40 --no-default-model --no-filters --spike-lengths 4,16 \
  "${MODELS[@]}" --json $OUT/eval.json --markdown $OUT/eval.md
