#!/bin/bash
# The learned multichannel Wiener filter (bench/results/clean.md, "A learned multichannel Wiener filter"):
# fitted to the training takes by `mocap clean train --wiener` (models/clean-wiener.safetensors, segment 32,
# noise covariance at 5 degrees, seed 1), then the 116-take evaluation with the tuned filters, the shipped
# network and it; and the study on 40 validation takes at fixed noise levels (wiener_bound example).
# With --network [--resume]: a network trained on top of the Wiener filter (51 min here; shipped as
# models/clean-default.safetensors since session 7), and its evaluation; with --despike: the shipped model and the
# Wiener filter followed by spike finding; with --base-input [--resume]: the network that also reads the Wiener
# filter's output and noise level (session 8), and its evaluations.
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
if [ "$1" == "--base-input" ]; then
  # The same network reading also the Wiener filter's output and the noise level it estimated
  # (`--base-input`, session 8; same recipe otherwise), evaluated with the filters at the report's noise (max 10
  # degrees) and, without the filters, on clean takes (--max-sigma 0) and at low noise (--max-sigma 2), against
  # the Wiener filter alone and the network without those inputs (shipped in session 7).
  $BIN/clean_train --data $DATA --width 64 --window 32 --base-wiener models/clean-wiener.safetensors --base-context 128 \
    --base-input --out $OUT/base-input.safetensors --state $OUT/base-input.state --plot $OUT/base-input.png \
    --epochs 12 --steps 40 --batch 256 --seed 1 --loss derivative --json $OUT/base-input-train.json $2
  # The session-7 network: from `--network`, or as shipped then.
  [ -f $OUT/wiener-base.safetensors ] || git show 8d96d2c:models/clean-default.safetensors > $OUT/wiener-base.safetensors
  MODELS=(--model "Wiener filter (learned, multichannel)=models/clean-wiener.safetensors"
          --model "network on the Wiener filter (session 7)=$OUT/wiener-base.safetensors"
          --model "network reading the Wiener filter's output and level=$OUT/base-input.safetensors")
  $BIN/clean_eval --data $DATA --tune-takes 12 --spike-lengths 2,4,8,16,32,64 --no-default-model "${MODELS[@]}" \
    --json $OUT/eval-base-input.json --markdown $OUT/eval-base-input.md
  for sigma in 0 2; do
    $BIN/clean_eval --data $DATA --spike-lengths "" --no-filters --no-default-model --max-sigma $sigma "${MODELS[@]}" \
      --json $OUT/eval-base-input-sigma$sigma.json --markdown $OUT/eval-base-input-sigma$sigma.md
  done
  # Spike finding after it, tuned on 40 validation takes (spans 1-8); "default model" is this model once shipped.
  $BIN/clean_eval --data $DATA --tune-takes 40 --no-filters --despike --spike-lengths 2,4,8,16,32,64 \
    --json $OUT/eval-base-input-despike.json --markdown $OUT/eval-base-input-despike.md
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
