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
$BIN/clean_train --data $DATA --out bench/clean/long-window.safetensors --state bench/clean/long-window.state \
  --plot bench/clean/long-window.png --window 64 --levels 3 --batch 128 --epochs 20 --steps 40 --seed 1 \
  --json bench/clean/long-window-train.json

# 3. The shipped default, resumed from its first 20 epochs up to 40 epochs.
$BIN/clean_train --data $DATA --out models/clean-default.safetensors --state bench/clean/default.state \
  --plot bench/results/clean-default-training.png --epochs 40 --steps 40 --batch 512 --seed 1 --resume \
  --json bench/clean/default-train.json

# Rotation representations and the position term (equal short budgets, first 40 test takes).
bench/clean/compare_representations.sh
bench/clean/position_loss.sh 0.001 0.01 0.1

# 4. The shipped default continued at lower learning rates (same data stream, Adam state kept):
#    epochs 41-50 at lr 3e-4, then 51-60 at lr 1e-4; the result replaced models/clean-default.safetensors
#    after the 116-take evaluation (bench/clean/finetune/eval.md) measured it better on every metric.
bench/clean/finetune.sh lr3e-4 50 3e-4 0
bench/clean/finetune.sh lr1e-4 60 1e-4 0 bench/clean/finetune/lr3e-4.state
cp bench/clean/finetune/lr1e-4.safetensors models/clean-default.safetensors
cp bench/clean/finetune/lr1e-4.png bench/results/clean-default-training.png

# 5. The shipped model since: width 64 (1,019,396 parameters), 6 epochs x 20 steps (width.sh), then
#    epochs 7-20 x 40 steps at lr 1e-3 and 21-24 at lr 3e-4 (width_long.sh); better than step 4's model on
#    every metric of the 116-take evaluation (bench/clean/width/eval-long.md), so it replaced it.
bench/clean/width.sh
bench/clean/width_long.sh
cp bench/clean/width/w64-long.safetensors models/clean-default.safetensors
cp bench/clean/width/w64-long.png bench/results/clean-default-training.png
# 6. Then continued (width_longer.sh): epochs 25-32 at lr 3e-4, 33-36 at lr 1e-4; better again on every metric
#    (bench/clean/width/eval-longer.md), so it replaced step 5's model.
bench/clean/width_longer.sh
cp bench/clean/width/w64-longer.safetensors models/clean-default.safetensors
cp bench/clean/width/w64-longer.png bench/results/clean-default-training.png
