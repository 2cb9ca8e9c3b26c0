#!/bin/bash
# A wider network (session 26; bench/results/clean.md, "A wider network under the Wiener filter"): the shipped
# network's recipe (session 8: reading and correcting the learned Wiener filter's output and level, 32-frame
# windows, 12 epochs x 40 steps x 256 windows, derivative loss, seed 1) at width 96 instead of 64, about 4.3 min per
# epoch on this CPU. Session 26 stopped it after 5 epochs, its validation MSE above width 64's at every epoch;
# the per-epoch losses are bench/clean/width96/progress.json (the state's progress file), to be compared with
# bench/clean/wiener/base-input-train.json. It was not rebased on the mixture or evaluated.
# Binaries: cargo build --profile test -p mocap-clean --examples (BIN below). --resume continues the state.
set -e
cd "$(dirname "$0")/../.."
BIN=${BIN:-./target/debug/examples}
DATA=../shared/data/bandai
OUT=bench/clean/width96
mkdir -p $OUT
$BIN/clean_train --data $DATA --width 96 --window 32 \
  --base-wiener models/clean-wiener.safetensors --base-context 128 --base-input \
  --out $OUT/network.safetensors --state $OUT/network.state --plot $OUT/network.png \
  --epochs 12 --steps 40 --batch 256 --seed 1 --loss derivative --json $OUT/train.json "$@"
cp $OUT/network.state/progress.json $OUT/progress.json
