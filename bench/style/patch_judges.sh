#!/usr/bin/env bash
# Reproduces bench/style/out/patch-judges.md: elastic patches at 32 and 48
# frames judged by the three style judges (forest, conv net, both) with seeds
# 1-3, both folds pooled. With other settings, bench/style/out/fixed-judges.md:
#
#   bash bench/style/patch_judges.sh   # PATCHES="32 48", JUDGES="forest conv-net both";
#                                      # a forest run takes 25 s, a conv-net or both run 3 min
#   METHODS=fixed-patches PATCHES=48 RUNS_DIR=/tmp/style-fixed-judges \
#     OUT_TABLE=bench/style/out/fixed-judges.md bash bench/style/patch_judges.sh
#   LAST_MODEL=M1 FIRST_MODEL=M2 ...   # other models of the two folds (default: the shipped
#                                      # model and the other fold's model of run.sh --other-fold)
#
# Needs the other fold's model (bash bench/style/run.sh --other-fold). The
# per-run reports stay in ${RUNS_DIR:-/tmp/style-patch-judges}.
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
        "$MOCAP" style eval "$DATA/dataset-1" "$DATA/dataset-2" "${PAIRS[@]}" "${FOLD_ARGS[@]}" \
          --patch "$P" --methods "${METHODS:-elastic-patches}" --style-judge "$judge" \
          --seed "$seed" --json > "$report.tmp"
        mv "$report.tmp" "$report"
      done
    done
  done
done
python3 bench/style/patch_judges_table.py "$RUNS" > "${OUT_TABLE:-$OUT/patch-judges.md}"
