#!/usr/bin/env bash
# Three style judges side by side (bench/results/style.md, "A second judge: a
# small conv net"): the forest on gait descriptors (the evaluation's judge), a
# small conv net on per-frame pose values, and both with their votes added
# (session 20), judge seeds 1-3, on both folds:
# first on real clips (cross-validation leaving one walking content out, and
# the held-out walks), then judging the outputs of every method.
#
#   bash bench/style/judges.sh     # about 90 min on the 2-core machine (the third judge: 16 min on
#                                  # real clips and 27 min of evaluations, measured in session 20)
#
# Needs the other fold's model, which `bash bench/style/run.sh --other-fold`
# trains (${MODEL_DIR:-/tmp}/style-fold-first.safetensors). The per-run JSON
# reports (about 1 MB each) stay in ${RUNS_DIR:-/tmp/style-judges}; the tables
# go to bench/style/out/judges.md.
source "$(dirname "$0")/setup.sh"
require_fold_model
RUNS=${RUNS_DIR:-/tmp/style-judges}
mkdir -p "$RUNS"
for judge in forest conv-net both; do
  for seed in 1 2 3; do
    for fold in last first; do
      FOLD_ARGS=(--held-out "$fold")
      [[ $fold == first ]] && FOLD_ARGS+=(--model "$FOLD_MODEL")
      "$BIN/classifiers" --held-out "$fold" --seed "$seed" --cv-style \
        --classifier-contents "$WALKS" --style-judge "$judge" "$DATA/dataset-1" \
        > "$RUNS/classifiers-$judge-$fold-seed$seed.json"
      "$BIN/style_eval" "${FOLD_ARGS[@]}" --style-judge "$judge" --seed "$seed" \
        --sources walk,walk-turn-left,walk-turn-right --styles walk \
        --classifier-contents "$WALKS" --json "$RUNS/eval-$judge-$fold-seed$seed.json" \
        "$DATA/dataset-1" "$DATA/dataset-2" > /dev/null
    done
  done
done
python3 bench/style/judges_table.py "$RUNS" > "$OUT/judges.md"
