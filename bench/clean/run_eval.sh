#!/bin/bash
# The evaluation of bench/results/clean.md ("Evaluation on the 116 test takes"): noisy input, the four
# classical filters (tuned on 12 validation takes per condition), the shipped model (trained by
# bench/clean/base_filter.sh --window32), the same with 16-frame windows (bench/clean/base_filter.sh), the report's model without a base filter (bench/clean/plain_model.sh), the
# model shipped before this session (trained on the earlier noise, for reference), each also followed by
# spike finding (tuned per method), on every test take of ../shared/data/bandai, under three noise conditions
# (random; spikes on random noise; spikes alone); then the speed benchmark.
# Binaries: CARGO_TARGET_DIR=target-clean cargo build --profile test -p mocap-clean --examples
set -e
cd "$(dirname "$0")/../.."
BIN=./target-clean/debug/examples
DATA=../shared/data/bandai
PREVIOUS=bench/clean/default/previous-default.safetensors
if [ ! -f $PREVIOUS ]; then mkdir -p bench/clean/default; git show 7ade215:models/clean-default.safetensors > $PREVIOUS; fi
$BIN/clean_eval --data $DATA --tune-takes 12 --despike \
  --model "model on the filter, window 16=bench/clean/base-filter/butterworth-base.safetensors" \
  --model "plain model (no base filter)=bench/clean/plain/plain.safetensors" \
  --model "previous model (earlier noise)=$PREVIOUS" \
  --json bench/clean/eval.json --markdown bench/clean/eval.md
$BIN/clean_speed --data $DATA --frames 1800 --repeats 5 --train-steps 5 --batch 512 | tee bench/clean/speed.txt
