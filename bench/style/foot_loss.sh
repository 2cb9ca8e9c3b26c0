#!/usr/bin/env bash
# The loss on the feet when training the style autoencoder (session 18;
# bench/results/style.md, "A loss on the feet"). Trains models with the
# shipped recipe and --foot-loss W (seeds 1 and 2, and the other fold), then
# measures each: flat-foot sliding of the sources through the autoencoder
# and of the outputs (example foot_cleanup) and the evaluation's judges
# (style_eval). Since session 19 the shipped recipe has weight 300, so the
# weight-0 models (the recipe before it) are trained here too. About 80
# minutes on the 2-core machine (each training 6-9 min).
#
#   bash bench/style/foot_loss.sh                 # train, then measure
#   bash bench/style/foot_loss.sh --measure-only  # measure models already trained
source "$(dirname "$0")/setup.sh"
M=${MODEL_DIR:-/tmp}/style-foot
F=$OUT/foot-loss
mkdir -p "$F"
train() { # NAME SEED WEIGHT [extra style_train options]
  local name=$1 seed=$2 weight=$3
  shift 3
  "$BIN/style_train" --epochs 30 --steps 100 --seed "$seed" --contents "$WALKS" \
    --foot-loss "$weight" "$@" -o "$M-$name.safetensors" \
    "$DATA/dataset-1" "$DATA/dataset-2" > "$F/train-$name.json"
}
measure() { # NAME MODEL [extra options: --held-out first]
  local name=$1 model=$2
  shift 2
  "$BIN/foot_cleanup" --model "$model" "$@" "$DATA/dataset-1" "$DATA/dataset-2" \
    > "$F/feet-$name.md"
  "$BIN/style_eval" --model "$model" "$@" --sources walk,walk-turn-left,walk-turn-right \
    --styles walk --classifier-contents "$WALKS" --json "$F/eval-$name.json" \
    --markdown "$F/eval-$name.md" "$DATA/dataset-1" "$DATA/dataset-2" > /dev/null
}
if [[ "${1:-}" != --measure-only ]]; then
  train s1-w0 1 0
  train s1-w300 1 300
  train s1-w1000 1 1000
  train s2-w0 2 0
  train s2-w300 2 300
  train first-w0 1 0 --held-out first
  train first-w300 1 300 --held-out first
fi
for name in s1-w0 s1-w300 s1-w1000 s2-w0 s2-w300; do
  measure "$name" "$M-$name.safetensors"
done
# The other fold, without and with the loss on the feet.
for name in first-w0 first-w300; do
  measure "$name" "$M-$name.safetensors" --held-out first
done
# The shipped-fold models of seed 1 judged with the forest's seeds 2 and 3 too
# (the judges' own spread; judges.sh does all judges, seeds and folds).
for name in s1-w0 s1-w300; do
  model=$M-$name.safetensors
  for seed in 2 3; do
    "$BIN/style_eval" --model "$model" --seed "$seed" --methods elastic-patches \
      --sources walk,walk-turn-left,walk-turn-right --styles walk --classifier-contents "$WALKS" \
      --json "$F/eval-$name-judge$seed.json" --markdown "$F/eval-$name-judge$seed.md" \
      "$DATA/dataset-1" "$DATA/dataset-2" > /dev/null
  done
done
python3 bench/style/foot_loss_table.py "$F" > "$F/summary.md"
cat "$F/summary.md"
