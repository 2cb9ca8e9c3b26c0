#!/usr/bin/env bash
# Reproduces bench/style/out/asymmetry.md (bench/results/style.md, "Turns kept
# along the take"): the evaluation of run.sh and run.sh --other-fold with the
# two other `--asymmetry` settings (`source-clip`: one offset per clip;
# `style`: the report's, the style's symmetric statistics alone), then takes
# that walk straight and then turn (or turn, then walk), joined from held-out
# dataset-2 clips and restyled with each setting (study style_asymmetry_along).
# About 7 minutes; run after run.sh and run.sh --other-fold, whose eval.json
# files are the default's side. The other settings' reports (about 1 MB each)
# stay in ${RUNS_DIR:-/tmp/style-asymmetry}.
source "$(dirname "$0")/setup.sh"
require_fold_model
RUNS=${RUNS_DIR:-/tmp/style-asymmetry}
mkdir -p "$RUNS"
for ASYMMETRY in style source-clip; do
  "$MOCAP" style eval "$DATA/dataset-1" "$DATA/dataset-2" "${PAIRS[@]}" --asymmetry "$ASYMMETRY" \
    --json > "$RUNS/eval-$ASYMMETRY-last.json"
  "$MOCAP" style eval "$DATA/dataset-1" "$DATA/dataset-2" "${PAIRS[@]}" --asymmetry "$ASYMMETRY" \
    --held-out first --model "$FOLD_MODEL" --json > "$RUNS/eval-$ASYMMETRY-first.json"
done
{
  python3 bench/style/asymmetry_table.py "$RUNS"
  echo
  echo "## Takes that walk straight and then turn"
  echo
  echo "Shipped fold (last take held out, the shipped model):"
  echo
  "$BIN/style_asymmetry_along" "$DATA/dataset-2" 2> /dev/null
  echo
  echo "Other fold (first take held out, its model):"
  echo
  "$BIN/style_asymmetry_along" "$DATA/dataset-2" --held-out first --model "$FOLD_MODEL" 2> /dev/null
} > "$OUT/asymmetry.md"
