#!/bin/bash
# The learned multichannel Wiener filter (bench/results/clean.md, "A learned multichannel Wiener filter"):
# fitted to the training takes by `mocap clean train --wiener` (models/clean-wiener.safetensors, segment 32,
# noise covariance at 5 degrees, seed 1), then the 116-take evaluation with the tuned filters, the shipped
# network and it; and the study on 40 validation takes at fixed noise levels (wiener_bound example).
# With --network [--resume]: a network trained on top of the Wiener filter (51 min here; shipped as
# models/clean-default.safetensors since session 7), and its evaluation; with --despike: the shipped model and the
# Wiener filter followed by spike finding.
# Binaries: cargo build -p mocap-cli; CARGO_TARGET_DIR=target-clean cargo build --profile test -p mocap-clean --examples
set -e
cd "$(dirname "$0")/../.."
BIN=./target-clean/debug/examples
DATA=../shared/data/bandai
OUT=bench/clean/wiener
mkdir -p $OUT
if [ "$1" == "--network" ]; then
  # The network on top of the Wiener filter: the recipe of the GCV-based model (width 64, 32-frame windows,
  # derivative loss, 12 epochs x 40 steps x 256 windows, lr 1e-3, seed 1) with --base-wiener and --base-context 128.
  $BIN/clean_train --data $DATA --width 64 --window 32 --base-wiener models/clean-wiener.safetensors --base-context 128 \
    --out $OUT/wiener-base.safetensors --state $OUT/wiener-base.state --plot $OUT/wiener-base.png \
    --epochs 12 --steps 40 --batch 256 --seed 1 --loss derivative --json $OUT/wiener-base-train.json $2
  $BIN/clean_eval --data $DATA --tune-takes 12 --spike-lengths 2,4,8,16,32,64 \
    --model "Wiener filter (learned, multichannel)=models/clean-wiener.safetensors" \
    --model "network on the Wiener filter=$OUT/wiener-base.safetensors" \
    --json $OUT/eval-network.json --markdown $OUT/eval-network.md
  exit 0
fi
if [ "$1" == "--despike" ]; then
  # The shipped model (the network on the Wiener filter since session 7) and the Wiener filter, each also
  # followed by spike finding (tuned per method on the validation takes).
  $BIN/clean_eval --data $DATA --tune-takes 12 --despike --spike-lengths 2,4,8,16,32,64 \
    --model "Wiener filter (learned, multichannel)=models/clean-wiener.safetensors" \
    --json $OUT/eval-despike.json --markdown $OUT/eval-despike.md
  exit 0
fi
if [ "$1" != "--eval-only" ]; then
  ./target/debug/mocap clean train $DATA --wiener -o models/clean-wiener.safetensors --json > $OUT/fit.json
fi
$BIN/clean_eval --data $DATA --tune-takes 12 --spike-lengths 2,4,8,16,32,64 \
  --model "Wiener filter (learned, multichannel)=models/clean-wiener.safetensors" \
  --json $OUT/eval.json --markdown $OUT/eval.md
$BIN/wiener_bound $DATA 40 > $OUT/study.md
for segment in 16 24 64 128; do  # 32 is the study above
  $BIN/wiener_bound $DATA 40 2,6,10 $segment > $OUT/study-segment-$segment.md
done
