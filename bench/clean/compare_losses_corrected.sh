#!/bin/bash
# The report's comparison (plain MSE vs the derivative loss) redone on the corrected noise and run until the
# validation loss flattens: 3 seeds x 2 losses, small network (width 32), 20 epochs x 40 steps x 512 windows,
# same data stream and validation windows per seed (bench/results/clean.md, "MSE against the derivative loss").
# Binaries: CARGO_TARGET_DIR=target-clean cargo build --profile test -p mocap-clean --examples
set -e
cd "$(dirname "$0")/../.."
./target-clean/debug/examples/compare_losses --data ../shared/data/bandai --out-dir bench/clean/compare-corrected \
  --seeds 1,2,3 --epochs 20 --steps 40 --batch 512 --auc-epochs 3
