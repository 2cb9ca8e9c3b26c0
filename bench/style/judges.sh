#!/usr/bin/env bash
# Reproduces bench/style/out/judges.md (bench/results/style.md, "Three judges,
# three seeds"): the forest on gait descriptors (the evaluation's judge), the
# small conv net and both with their votes added, judge seeds 1-3, both folds;
# first on real clips (cross-validation leaving one walking content out, and
# the held-out walks), then judging the outputs of every method.
#
#   bash bench/style/judges.sh     # about 90 min on a 2-core machine
#
# Needs the other fold's model (bash bench/style/run.sh --other-fold). The
# per-run JSON reports (about 1 MB each) stay in ${RUNS_DIR:-/tmp/style-judges}.
source "$(dirname "$0")/setup.sh"
require_fold_model
RUNS=${RUNS_DIR:-/tmp/style-judges}
mkdir -p "$RUNS"
for judge in forest conv-net both; do
  for seed in 1 2 3; do
    for fold in last first; do
      FOLD_ARGS=(--held-out "$fold")
      [[ $fold == first ]] && FOLD_ARGS+=(--model "$FOLD_MODEL")
      "$BIN/style_classifiers" --held-out "$fold" --seed "$seed" --cv-style \
        --classifier-contents "$WALKS" --style-judge "$judge" "$DATA/dataset-1" \
        > "$RUNS/classifiers-$judge-$fold-seed$seed.json"
      "$MOCAP" style eval "$DATA/dataset-1" "$DATA/dataset-2" "${PAIRS[@]}" "${FOLD_ARGS[@]}" \
        --style-judge "$judge" --seed "$seed" --json > "$RUNS/eval-$judge-$fold-seed$seed.json"
    done
  done
done
python3 bench/style/judges_table.py "$RUNS" > "$OUT/judges.md"
