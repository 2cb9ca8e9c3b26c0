#!/usr/bin/env bash
# Reproduces bench/style/out/patch-select.md: every patch length P evaluated on
# both folds (the shipped model with the last takes held out, the other fold's
# model with the first takes held out); patch_select.py picks P on one fold and
# reports what that P gives on the other. About 9 minutes on a 2-core machine.
# Needs the other fold's model (bash bench/style/run.sh --other-fold). The
# per-run reports stay in ${RUNS_DIR:-/tmp/style-patch-select}.
source "$(dirname "$0")/setup.sh"
require_fold_model
RUNS=${RUNS_DIR:-/tmp/style-patch-select}
mkdir -p "$RUNS"
for P in ${PATCHES:-24 32 40 48 56 64 72}; do
  for fold in last first; do
    FOLD_ARGS=(--held-out "$fold")
    [[ $fold == first ]] && FOLD_ARGS+=(--model "$FOLD_MODEL")
    "$MOCAP" style eval "$DATA/dataset-1" "$DATA/dataset-2" "${PAIRS[@]}" "${FOLD_ARGS[@]}" \
      --patch "$P" --methods elastic-patches,fixed-patches --json > "$RUNS/eval-p$P-$fold.json"
  done
done
python3 bench/style/patch_select.py "$RUNS" > "$OUT/patch-select.md"
