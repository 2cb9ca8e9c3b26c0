#!/usr/bin/env bash
# Choosing the patch length P without looking at the pairs it is judged on:
# every P is evaluated on both folds (the shipped model on the last takes held
# out, the other fold's model on the first takes held out); patch_select.py
# picks P on one fold and reports what that P gives on the other.
# Needs the other fold's model (bash bench/style/run.sh --other-fold).
# About 9 minutes on the 2-core machine.
source "$(dirname "$0")/setup.sh"
require_fold_model
RUNS=$OUT/patch-select
mkdir -p "$RUNS"
for P in ${PATCHES:-24 32 40 48 56 64 72}; do
  for fold in last first; do
    FOLD_ARGS=(--held-out "$fold")
    [[ $fold == first ]] && FOLD_ARGS+=(--model "$FOLD_MODEL")
    "$BIN/style_eval" "${FOLD_ARGS[@]}" --patch "$P" --methods elastic-patches,fixed-patches \
      --sources walk,walk-turn-left,walk-turn-right --styles walk \
      --classifier-contents "$WALKS" --json "$RUNS/eval-p$P-$fold.json" \
      "$DATA/dataset-1" "$DATA/dataset-2" > /dev/null
  done
done
python3 bench/style/patch_select.py "$RUNS" > "$OUT/patch-select.md"
