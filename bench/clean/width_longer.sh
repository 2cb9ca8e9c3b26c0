#!/bin/bash
# The width-64 model of width_long.sh continued: epochs 25-32 at lr 3e-4, 33-36 at lr 1e-4 (40 steps x 512).
set -e
cd "$(dirname "$0")/../.."
BIN=./target-clean/debug/examples
DATA=../shared/data/bandai
OUT=bench/clean/width
if [ ! -d $OUT/w64-longer.state ]; then cp -r $OUT/w64-long.state $OUT/w64-longer.state; fi
COMMON="--data $DATA --width 64 --out $OUT/w64-longer.safetensors --state $OUT/w64-longer.state --plot $OUT/w64-longer.png --steps 40 --batch 512 --seed 1 --loss derivative --resume"
$BIN/clean_train $COMMON --epochs 32 --lr 3e-4 --json $OUT/w64-longer-c-train.json
$BIN/clean_train $COMMON --epochs 36 --lr 1e-4 --json $OUT/w64-longer-d-train.json
