#!/bin/bash
# A wider network (session 26; bench/results/clean.md, "A wider network on the Wiener mixture"): the shipped
# model's recipe (session 8: reading and correcting the learned Wiener filter's output and level, 32-frame
# windows, 12 epochs x 40 steps x 256 windows, derivative loss, seed 1) at width 96 instead of 64 (about 50 min
# on this CPU), rebased on the shipped mixture as the shipped network was (session 10), then judged against the
# shipped model: the evaluation's noise with spike finding (clean_eval --despike), six draws of it
# (spike_draws, MOCAP_CLEAN_MODEL), clean takes (--max-sigma 0) and speed.
# Binaries: cargo build --profile test -p mocap-cli -p mocap-clean --examples (BIN, MOCAP below)
set -e
cd "$(dirname "$0")/../.."
BIN=${BIN:-./target/debug/examples}
MOCAP=${MOCAP:-./target/debug/mocap}
DATA=../shared/data/bandai
OUT=bench/clean/width96
mkdir -p $OUT
[ -f $OUT/network.safetensors ] || $BIN/clean_train --data $DATA --width 96 --window 32 \
  --base-wiener models/clean-wiener.safetensors --base-context 128 --base-input \
  --out $OUT/network.safetensors --state $OUT/network.state --plot $OUT/network.png \
  --epochs 12 --steps 40 --batch 256 --seed 1 --loss derivative --json $OUT/train.json
[ -f $OUT/mixture.safetensors ] || $MOCAP clean train $DATA --wiener --mixture 150 \
  --rebase $OUT/network.safetensors -o $OUT/mixture.safetensors --json > $OUT/rebase.json
NEW="width 96 on the mixture=$OUT/mixture.safetensors"
$BIN/clean_eval --data $DATA --tune-takes 12 --no-filters --despike --spike-lengths "" --model "$NEW" \
  --json $OUT/eval-despike.json --markdown $OUT/eval-despike.md
$BIN/clean_eval --data $DATA --spike-lengths "" --no-filters --max-sigma 0 --model "$NEW" \
  --json $OUT/eval-sigma0.json --markdown $OUT/eval-sigma0.md
MOCAP_CLEAN_MODEL=$OUT/mixture.safetensors $BIN/spike_draws $DATA 7,8,9,10,11,12 > $OUT/draws.md
for model in models/clean-default.safetensors $OUT/mixture.safetensors; do
  $BIN/clean_speed --data $DATA --model $model --frames 1800 --repeats 5 --train-steps 0
done > $OUT/speed.txt
