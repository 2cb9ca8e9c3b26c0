#!/bin/bash
# A wider network trained longer (candidate shipped model): the width-64 run of width.sh
# (6 epochs x 20 steps x 512) continued with 40 steps per epoch, epochs 7-20 at lr 1e-3 and 21-24 at lr 3e-4.
set -e
cd "$(dirname "$0")/../.."
BIN=./target-clean/debug/examples
DATA=../shared/data/bandai
OUT=bench/clean/width
if [ ! -d $OUT/w64-long.state ]; then cp -r $OUT/w64.state $OUT/w64-long.state; fi
COMMON="--data $DATA --width 64 --out $OUT/w64-long.safetensors --state $OUT/w64-long.state --plot $OUT/w64-long.png --steps 40 --batch 512 --seed 1 --loss derivative --resume"
$BIN/clean_train $COMMON --epochs 20 --lr 1e-3 --json $OUT/w64-long-a-train.json
$BIN/clean_train $COMMON --epochs 24 --lr 3e-4 --json $OUT/w64-long-b-train.json
