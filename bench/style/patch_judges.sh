#!/usr/bin/env bash
# The patch length patch_select.sh chooses, judged by all three style judges
# (the forest, the conv net, both: judges.sh) with seeds 1-3 on both folds,
# side by side with the default P = 32 on the same models: elastic patches
# by default. Session 24 (bench/results/style.md, "The patch length, again");
# session 25 ran the fixed patches the same way at 48 frames.
#
#   bash bench/style/patch_judges.sh   # PATCHES="32 48", JUDGES="forest conv-net both" by default:
#                                      # a forest run takes 25 s, a conv-net or both run 3 min
#   METHODS=fixed-patches PATCHES=48 RUNS_DIR=/tmp/style-fixed-judges \
#     OUT_TABLE=bench/style/out/fixed-judges.md bash bench/style/patch_judges.sh
#                                      # METHODS: style_eval's --methods list
#   LAST_MODEL=M1 FIRST_MODEL=M2 ...   # other models of the two folds (default: the shipped
#                                      # model and the other fold's model of run.sh --other-fold)
#
# Needs the other fold's model (bash bench/style/run.sh --other-fold). The
# per-run reports stay in ${RUNS_DIR:-/tmp/style-patch-judges}; the table
# goes to ${OUT_TABLE:-bench/style/out/patch-judges.md}.
source "$(dirname "$0")/setup.sh"
require_fold_model
RUNS=${RUNS_DIR:-/tmp/style-patch-judges}
mkdir -p "$RUNS"
for P in ${PATCHES:-32 48}; do
  for judge in ${JUDGES:-forest conv-net both}; do
    for seed in 1 2 3; do
      for fold in last first; do
        FOLD_ARGS=(--held-out "$fold")
        [[ $fold == first ]] && FOLD_ARGS+=(--model "${FIRST_MODEL:-$FOLD_MODEL}")
        [[ $fold == last && -n ${LAST_MODEL:-} ]] && FOLD_ARGS+=(--model "$LAST_MODEL")
        report=$RUNS/eval-p$P-$judge-$fold-seed$seed.json
        [[ -f $report ]] && continue
        "$BIN/style_eval" "${FOLD_ARGS[@]}" --patch "$P" --methods "${METHODS:-elastic-patches}" \
          --style-judge "$judge" --seed "$seed" \
          --sources walk,walk-turn-left,walk-turn-right --styles walk \
          --classifier-contents "$WALKS" --json "$report.tmp" \
          "$DATA/dataset-1" "$DATA/dataset-2" > /dev/null
        mv "$report.tmp" "$report"
      done
    done
  done
done
python3 bench/style/patch_judges_table.py "$RUNS" > "${OUT_TABLE:-$OUT/patch-judges.md}"
