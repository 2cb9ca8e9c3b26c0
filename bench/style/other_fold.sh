#!/usr/bin/env bash
# The style evaluation measured a second time, on the other fold: the FIRST
# take of every (set, content, style) group of two takes or more is held out
# (the shipped model and bench/style/run.sh hold out the last). A model is
# trained with the shipped recipe on the other takes (same seed), then the
# same evaluation runs. Results: bench/style/out/fold-first/, summarised in
# bench/results/style.md ("The other fold"). About 10 minutes on a quiet CPU.
set -euo pipefail
cd "$(dirname "$0")/../.."
DATA=${MOCAP_SHARED_DATA:-../shared/data}/bandai
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-target-style}
cargo build -q --profile test -p mocap-style --examples
BIN=$CARGO_TARGET_DIR/debug/examples
WALKS=walk,walk-back,walk-left,walk-right,walk-turn-left,walk-turn-right
OUT=bench/style/out/fold-first
MODEL=${MODEL_DIR:-/tmp}/style-fold-first.safetensors
mkdir -p "$OUT"
"$BIN/style_train" --held-out first --epochs 30 --steps 100 --seed 1 --contents "$WALKS" \
  -o "$MODEL" "$DATA/dataset-1" "$DATA/dataset-2" > "$OUT/train.json"
"$BIN/style_eval" --held-out first --model "$MODEL" \
  --sources walk,walk-turn-left,walk-turn-right --styles walk \
  --classifier-contents "$WALKS" --json "$OUT/eval.json" --markdown "$OUT/eval.md" \
  "$DATA/dataset-1" "$DATA/dataset-2"
"$BIN/classifiers" --held-out first --cv --classifier-contents "$WALKS" "$DATA/dataset-1" \
  > "$OUT/classifiers-d1.json"
