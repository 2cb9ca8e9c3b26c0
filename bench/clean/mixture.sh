#!/bin/bash
# The Wiener mixture (bench/results/clean.md, "A mixture of Wiener filters, one per kind of motion"):
# the shipped network (session 8, not retrained) rebased on a mixture built from its own Wiener filter
# (13 components: one per content with at least 150 training segments, one for the rest, the filter's own
# spectra), written as models/clean-default.safetensors; the mixture alone; the 116-take evaluations; the
# study on 40 validation takes at fixed noise levels.
# Binaries: cargo build -p mocap-cli; CARGO_TARGET_DIR=target-clean cargo build --profile test -p mocap-clean --examples
# With --fit: refit first (about 5 min each; the session-8 network is taken from git, commit 399ad2b).
set -e
cd "$(dirname "$0")/../.."
BIN=./target-clean/debug/examples
DATA=../shared/data/bandai
OUT=bench/clean/mixture
mkdir -p $OUT
PREVIOUS=$OUT/session8-default.safetensors
[ -f $PREVIOUS ] || git show 399ad2b:models/clean-default.safetensors > $PREVIOUS
if [ "$1" == "--fit" ]; then
  ./target/debug/mocap clean train $DATA --wiener --mixture 150 --rebase $PREVIOUS \
    -o models/clean-default.safetensors --json > $OUT/rebase.json
  python3 $OUT/dump_header.py models/clean-default.safetensors > models/clean-default.json
  ./target/debug/mocap clean train $DATA --wiener --mixture 150 -o $OUT/wiener-mixture.safetensors --json > $OUT/fit.json
fi
# With --network: the network retrained on the mixture (session 12, 2.7 h on this CPU; weights not in git),
# evaluated beside the shipped one (session 13, 19 min); only this part runs.
if [ "$1" == "--network" ]; then
  NET=bench/clean/mixture-net
  mkdir -p $NET
  [ -f $OUT/wiener-mixture.safetensors ] || { echo "$OUT/wiener-mixture.safetensors is missing: run with --fit first" >&2; exit 1; }
  [ -f $NET/network.safetensors ] || $BIN/clean_train --data $DATA --width 64 --window 32 \
    --base-wiener $OUT/wiener-mixture.safetensors --base-context 128 --base-input \
    --epochs 12 --steps 40 --batch 256 --seed 1 --loss derivative \
    --out $NET/network.safetensors --state $NET/network.state --json $NET/train.json
  $BIN/clean_eval --data $DATA --tune-takes 12 --no-filters --despike --spike-lengths 2,4,8,16,32,64 \
    --model "network retrained on the mixture=$NET/network.safetensors" \
    --json $NET/eval-despike.json --markdown $NET/eval-despike.md
  exit 0
fi
# The evaluation with the tuned filters: "default model" is the rebased network.
$BIN/clean_eval --data $DATA --tune-takes 12 --spike-lengths 2,4,8,16,32,64 \
  --model "network of session 8 on the single Wiener filter=$PREVIOUS" \
  --model "learned Wiener filter=models/clean-wiener.safetensors" \
  --model "Wiener mixture alone=$OUT/wiener-mixture.safetensors" \
  --json $OUT/eval.json --markdown $OUT/eval.md
# Clean and slightly noisy takes.
for sigma in 0 2; do
  $BIN/clean_eval --data $DATA --spike-lengths "" --no-filters --max-sigma $sigma \
    --model "network of session 8 on the single Wiener filter=$PREVIOUS" \
    --json $OUT/eval-sigma$sigma.json --markdown $OUT/eval-sigma$sigma.md
done
# Spike finding before the model (mocap clean --despike), its settings tuned on 12 validation takes.
$BIN/clean_eval --data $DATA --tune-takes 12 --no-filters --despike --spike-lengths 2,4,8,16,32,64 \
  --json $OUT/eval-despike.json --markdown $OUT/eval-despike.md
# The study: one filter against the mixture on 40 validation takes at fixed levels.
$BIN/wiener_mixture $DATA 40 0,1,2,4,6,8,10 150 > $OUT/study.md
# Spike finding settings and what it finds, on all 120 validation takes, with the shipped model (12 min).
$BIN/spike_finding $DATA 1000 > $OUT/finding.md
