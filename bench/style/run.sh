#!/usr/bin/env bash
# Reproduces bench/results/style.md: the evaluation of the shipped model on
# held-out Bandai pairs, the report's root, the familiarity of every clip and
# the time to restyle a 10-second clip; flags add the rest.
#
#   bash bench/style/run.sh               # evaluation, familiarity, speed (a few minutes)
#   bash bench/style/run.sh --train       # first retrain models/style-default.safetensors (22 min)
#   bash bench/style/run.sh --classifiers # also the judges on real clips (held out and cross-validated)
#   bash bench/style/run.sh --contacts    # also each root without and with the foot-contact cleanup
#   bash bench/style/run.sh --other-fold  # also train and evaluate the other fold (about 35 min)
#
# Flags combine. Runs whose JSON no page cites go to ${RUNS_DIR:-/tmp/style-runs}.
source "$(dirname "$0")/setup.sh"

ARGS=" $* "
flag() { [[ "$ARGS" == *" $1 "* ]]; }
RUNS=${RUNS_DIR:-/tmp/style-runs}
mkdir -p "$RUNS"

if flag --train; then
  # The shipped recipe: the report's setting (240-frame windows, batch 16,
  # Adam, lr 1e-4), the walking takes of both sets without the held-out
  # takes, with mirrored copies, seed 1, the loss on the planted feet at
  # weight 300, 9,000 steps (90 epochs of 100).
  "$MOCAP" style train "$DATA/dataset-1" "$DATA/dataset-2" --contents "$WALKS" \
    --epochs 90 --steps 100 --seed 1 --foot-loss 300 -o models/style-default.safetensors \
    --json > "$OUT/train.json"
  # The loss plot goes to bench/style; the resumable state is not shipped.
  cp models/style-default.png bench/style/loss.png
  rm -rf models/style-default.png models/style-default.state
  build
fi

if flag --classifiers; then
  # The evaluation's judges on real clips only (no restyling): held-out
  # accuracy and cross-validation on the training clips (style: leave one
  # content out; content: leave one style out). Content cross-validation on
  # dataset-2 (921 clips) is left out for time.
  "$BIN/style_classifiers" --cv --classifier-contents "$WALKS" "$DATA/dataset-1" \
    > "$OUT/classifiers-d1.json"
  "$BIN/style_classifiers" --cv-style --classifier-contents "$WALKS" "$DATA/dataset-2" \
    > "$OUT/classifiers-d2.json"
fi

# The default root (`--root feet-along-source`).
"$MOCAP" style eval "$DATA/dataset-1" "$DATA/dataset-2" "${PAIRS[@]}" \
  --filmstrips bench/style/filmstrips --markdown "$OUT/eval.md" --json > "$OUT/eval.json"
# The report's root: the source's path, time-warped.
"$MOCAP" style eval "$DATA/dataset-1" "$DATA/dataset-2" "${PAIRS[@]}" --root source \
  --markdown "$OUT/eval-root-source.md" --json > "$RUNS/eval-root-source.json"
# How far the shipped model reproduces every clip (apply's unfamiliar-source note).
"$BIN/style_familiarity" "$DATA/dataset-1" "$DATA/dataset-2" > "$OUT/familiarity.md"

"$BIN/style_speed" "$DATA/dataset-1/dataset-1_walk_not-confident_001.bvh" \
  "$DATA/dataset-1/dataset-1_walk_proud_002.bvh" --runs 20 --patches 48,32 | tee "$OUT/speed.md"

if flag --contacts; then
  # How much the feet slide (sources, through the autoencoder alone, outputs)
  # and the cleanup with its sweeps of the reach limit and the height test.
  "$BIN/style_foot_cleanup" --reach-limits 0.99,1,1.05,1.1 --height-tolerances 0.02,0.05 \
    "$DATA/dataset-1" "$DATA/dataset-2" > "$OUT/foot-cleanup.md"
  # Elastic and fixed patches with each root, without and with the cleanup.
  contacts() { # NAME [options]
    local name=$1
    shift
    "$MOCAP" style eval "$DATA/dataset-1" "$DATA/dataset-2" "${PAIRS[@]}" \
      --methods elastic-patches,fixed-patches "$@" \
      --markdown "$OUT/$name.md" --json > "$RUNS/$name.json"
  }
  contacts eval-contacts-default-root --foot-contacts
  contacts eval-contacts --root source --foot-contacts
  contacts eval-root-from-feet --root feet
  contacts eval-root-from-feet-contacts --root feet --foot-contacts
  python3 bench/style/contacts_table.py "$OUT" "$RUNS" > "$OUT/contacts-table.md"
fi

if flag --other-fold; then
  # The FIRST take of every (set, content, style) group of two takes or more
  # held out: a model trained with the shipped recipe on the other takes,
  # then the same evaluation and the judges on real clips.
  FOLD=$OUT/fold-first
  mkdir -p "$FOLD"
  "$MOCAP" style train "$DATA/dataset-1" "$DATA/dataset-2" --held-out first --contents "$WALKS" \
    --epochs 90 --steps 100 --seed 1 --foot-loss 300 -o "$FOLD_MODEL" --json > "$FOLD/train.json"
  "$MOCAP" style eval "$DATA/dataset-1" "$DATA/dataset-2" "${PAIRS[@]}" --held-out first \
    --model "$FOLD_MODEL" --markdown "$FOLD/eval.md" --json > "$FOLD/eval.json"
  "$BIN/style_classifiers" --held-out first --cv --classifier-contents "$WALKS" "$DATA/dataset-1" \
    > "$FOLD/classifiers-d1.json"
fi
