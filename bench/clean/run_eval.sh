#!/bin/bash
# The evaluation table of bench/results/clean.md: every test take (116), filters tuned on 12 validation takes,
# the shipped default model, the long-window model, and the 6-epoch MSE / derivative-loss runs of seed 1.
# Then the speed benchmark of the default model.
set -e
cd "$(dirname "$0")/../.."
BIN=./target-clean/debug/examples
DATA=../shared/data/bandai
$BIN/clean_eval --data $DATA --tune-takes 12 \
  --model "long-window model (T 64)=bench/clean/long-window.safetensors" \
  --model "MSE, 6 epochs (seed 1)=bench/clean/compare/mse-seed1.safetensors" \
  --model "derivative loss, 6 epochs (seed 1)=bench/clean/compare/derivative-seed1.safetensors" \
  --json bench/clean/eval.json --markdown bench/clean/eval.md
$BIN/clean_speed --data $DATA --frames 1800 --repeats 5 --train-steps 5 --batch 512 | tee bench/clean/speed.txt
$BIN/clean_speed --data $DATA --model bench/clean/long-window.safetensors --frames 1800 --repeats 5 --train-steps 0 | tee -a bench/clean/speed.txt
