#!/bin/bash
# Every measurement in bench/results/clean.md, in the order it was run.
# Binaries: CARGO_TARGET_DIR=target-clean cargo build --profile test -p mocap-clean --examples
# (the `test` profile: workspace crates at opt-level 1, dependencies, burn included, at opt-level 2).
set -e
cd "$(dirname "$0")/../.."
BIN=./target-clean/debug/examples
DATA=../shared/data/bandai

# 1. The report's comparison: plain MSE vs derivative loss, 3 seeds each, same data and validation windows.
$BIN/compare_losses --data $DATA --out-dir bench/clean/compare --seeds 1,2,3 --epochs 6 --steps 20 --batch 512 --auc-epochs 3

# 2. Long spikes: the same small network with a 64-frame window (3 levels), 128 windows per batch
#    (the same frames per step as 512 x 16).
$BIN/train --data $DATA --out bench/clean/long-window.safetensors --state bench/clean/long-window.state \
  --plot bench/clean/long-window.png --window 64 --levels 3 --batch 128 --epochs 20 --steps 40 --seed 1 \
  --json bench/clean/long-window-train.json

# 3. The shipped default, resumed from its first 20 epochs up to 40 epochs.
$BIN/train --data $DATA --out models/clean-default.safetensors --state bench/clean/default.state \
  --plot bench/results/clean-default-training.png --epochs 40 --steps 40 --batch 512 --seed 1 --resume \
  --json bench/clean/default-train.json
