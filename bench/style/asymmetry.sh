#!/usr/bin/env bash
# The source's left-right asymmetry: kept along the take (averaged over two
# strides around each frame; the default since session 17), kept as one offset
# per clip (`--asymmetry source-clip`, the default of session 16) and not kept
# (`--asymmetry style`, the report's method). First the same evaluation as
# run.sh and run.sh --other-fold with the two other settings, then takes that
# walk straight and then turn (or turn, then walk), joined from held-out
# dataset-2 clips and restyled with each setting (example asymmetry_along),
# then the tables (bench/results/style.md, "Turns kept"). About 7 minutes; run
# after run.sh and run.sh --other-fold, whose eval.json files are the
# default's side. The other settings' reports (about 1 MB each) stay in
# ${RUNS_DIR:-/tmp/style-asymmetry}.
#
#   bash bench/style/asymmetry.sh      # writes bench/style/out/asymmetry.md
source "$(dirname "$0")/setup.sh"
require_fold_model
RUNS=${RUNS_DIR:-/tmp/style-asymmetry}
mkdir -p "$RUNS"
for ASYMMETRY in style source-clip; do
  COMMON=(--asymmetry "$ASYMMETRY" --sources walk,walk-turn-left,walk-turn-right --styles walk
    --classifier-contents "$WALKS")
  "$BIN/style_eval" "${COMMON[@]}" --json "$RUNS/eval-$ASYMMETRY-last.json" \
    "$DATA/dataset-1" "$DATA/dataset-2" > /dev/null
  "$BIN/style_eval" "${COMMON[@]}" --held-out first --model "$FOLD_MODEL" \
    --json "$RUNS/eval-$ASYMMETRY-first.json" "$DATA/dataset-1" "$DATA/dataset-2" > /dev/null
done
{
  python3 bench/style/asymmetry_table.py "$RUNS"
  echo
  echo "## Takes that walk straight and then turn"
  echo
  echo "Shipped fold (last take held out, the shipped model):"
  echo
  "$BIN/asymmetry_along" "$DATA/dataset-2" 2> /dev/null
  echo
  echo "Other fold (first take held out, its model):"
  echo
  "$BIN/asymmetry_along" "$DATA/dataset-2" --held-out first --model "$FOLD_MODEL" 2> /dev/null
} > "$OUT/asymmetry.md"
