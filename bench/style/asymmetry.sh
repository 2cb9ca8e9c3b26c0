#!/usr/bin/env bash
# The source's left-right asymmetry kept (the default since session 16) against
# the report's method (`--asymmetry style`): the same evaluation as run.sh and
# run.sh --other-fold, with `--asymmetry style`, then a table of both
# (bench/results/style.md, "Turns kept"). About 4 minutes; run after run.sh
# and run.sh --other-fold, whose eval.json files are the default's side. The
# `--asymmetry style` reports (about 1 MB each) stay in
# ${RUNS_DIR:-/tmp/style-asymmetry}.
#
#   bash bench/style/asymmetry.sh      # writes bench/style/out/asymmetry.md
source "$(dirname "$0")/setup.sh"
require_fold_model
RUNS=${RUNS_DIR:-/tmp/style-asymmetry}
mkdir -p "$RUNS"
COMMON=(--asymmetry style --sources walk,walk-turn-left,walk-turn-right --styles walk
  --classifier-contents "$WALKS")
"$BIN/style_eval" "${COMMON[@]}" --json "$RUNS/eval-last.json" \
  "$DATA/dataset-1" "$DATA/dataset-2" > /dev/null
"$BIN/style_eval" "${COMMON[@]}" --held-out first --model "$FOLD_MODEL" \
  --json "$RUNS/eval-first.json" "$DATA/dataset-1" "$DATA/dataset-2" > /dev/null
python3 bench/style/asymmetry_table.py "$RUNS" > "$OUT/asymmetry.md"
