#!/usr/bin/env bash
# Training the shipped recipe twice as long, 180 epochs instead of 90, on both
# folds, judged against the 90-epoch models with 48-frame elastic patches
# (session 25; bench/results/style.md, "Longer still: 180 epochs"; measured,
# not shipped).
#
#   bash bench/style/long_training.sh   # about 70 min of training on the quiet 2-core machine
#                                       # (fold first resumes run.sh --other-fold's state at
#                                       # epoch 90), then about 2 min of forest runs and 12 min of
#                                       # conv-net runs per judge seed; JUDGES="forest conv-net"
#                                       # by default
#
# Needs the other fold's 90-epoch model and its training state
# (bash bench/style/run.sh --other-fold leaves both in ${MODEL_DIR:-/tmp}).
# Models: ${LONG_DIR:-/tmp/style-long}; reports: $LONG_DIR/runs-{90,180};
# the table goes to bench/style/out/long-training.md.
source "$(dirname "$0")/setup.sh"
require_fold_model
L=${LONG_DIR:-/tmp/style-long}
mkdir -p "$L"
TRAIN=(--steps 100 --seed 1 --contents "$WALKS" --foot-loss 300)
if [[ ! -f $L/first-180.json ]]; then
  # A resumed run draws the windows an uninterrupted one would, so this is
  # the 180-epoch recipe exactly.
  rm -rf "$L/first-180.state"
  cp -r "${FOLD_MODEL%.safetensors}.state" "$L/first-180.state"
  "$BIN/style_train" --held-out first --epochs 180 "${TRAIN[@]}" --resume \
    -o "$L/first-180.safetensors" "$DATA/dataset-1" "$DATA/dataset-2" > "$L/first-180.json.tmp"
  mv "$L/first-180.json.tmp" "$L/first-180.json"
fi
if [[ ! -f $L/last-180.json ]]; then
  "$BIN/style_train" --held-out last --epochs 180 "${TRAIN[@]}" \
    -o "$L/last-180.safetensors" "$DATA/dataset-1" "$DATA/dataset-2" > "$L/last-180.json.tmp"
  mv "$L/last-180.json.tmp" "$L/last-180.json"
fi
export PATCHES=48 JUDGES=${JUDGES:-forest conv-net}
RUNS_DIR=$L/runs-90 OUT_TABLE=$L/patch-judges-90.md bash bench/style/patch_judges.sh
RUNS_DIR=$L/runs-180 OUT_TABLE=$L/patch-judges-180.md LAST_MODEL=$L/last-180.safetensors \
  FIRST_MODEL=$L/first-180.safetensors bash bench/style/patch_judges.sh
python3 bench/style/models_table.py "90 epochs (shipped)=$L/runs-90" "180 epochs=$L/runs-180" \
  > "$OUT/long-training.md"
