#!/bin/bash
# Trains the report's model without a base filter ("plain model" in bench/results/clean.md; it was shipped
# for a few hours of session 3, until the model on top of the Butterworth filter beat it): width 64, window 16, 6D local rotations, derivative loss, the default noise (random noise on every window,
# none on the joints above the pelvis; spikes on half of them), Adam with batch 512 and a stepped learning
# rate: epochs 1-20 at 1e-3, 21-28 at 3e-4, 29-32 at 1e-4 (40 steps each: 655,360 windows in all).
# Binaries: CARGO_TARGET_DIR=target-clean cargo build --profile test -p mocap-clean --examples
set -e
cd "$(dirname "$0")/../.."
BIN=./target-clean/debug/examples
DATA=../shared/data/bandai
OUT=bench/clean/plain
mkdir -p $OUT
COMMON="--data $DATA --width 64 --out $OUT/plain.safetensors --state $OUT/plain.state --plot $OUT/plain.png --steps 40 --batch 512 --seed 1 --loss derivative --resume"
$BIN/clean_train $COMMON --epochs 20 --lr 1e-3 --json $OUT/stage-a-train.json
$BIN/clean_train $COMMON --epochs 28 --lr 3e-4 --json $OUT/stage-b-train.json
$BIN/clean_train $COMMON --epochs 32 --lr 1e-4 --json $OUT/stage-c-train.json
