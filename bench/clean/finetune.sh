#!/bin/bash
# Continuing the shipped default model (40 epochs x 40 steps x 512, lr 1e-3, state in
# bench/clean/default.state) for more epochs at a lower learning rate, with or without the position
# term. Each run copies the default's training state, so the default itself is untouched.
# Usage: bench/clean/finetune.sh NAME EPOCHS LR POSITION_WEIGHT [FROM_STATE]
#   EPOCHS = total (e.g. 50); FROM_STATE = the state to continue (default bench/clean/default.state).
set -e
cd "$(dirname "$0")/../.."
BIN=./target-clean/debug/examples
DATA=../shared/data/bandai
OUT=bench/clean/finetune
NAME=$1; EPOCHS=$2; LR=$3; W=$4; FROM=${5:-bench/clean/default.state}
mkdir -p $OUT
if [ ! -d $OUT/$NAME.state ]; then cp -r $FROM $OUT/$NAME.state; fi
$BIN/clean_train --data $DATA --out $OUT/$NAME.safetensors --state $OUT/$NAME.state --plot $OUT/$NAME.png \
  --epochs $EPOCHS --steps 40 --batch 512 --seed 1 --lr $LR --position-weight $W --resume \
  --json $OUT/$NAME-train.json
