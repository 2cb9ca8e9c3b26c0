#!/usr/bin/env bash
# Session 13: the style autoencoder trained on mirrored copies before and
# after the fix to mocap_core::ops::mirror (bench/results/style.md, "Mirrored
# copies fixed"): three seeds each, trained with the shipped recipe and
# evaluated with today's evaluation. About 35 minutes on the 2-core machine.
#
#   bash bench/style/mirror_fix.sh
#   python3 bench/style/seeds_table.py bench/style/out/mirror-fix
#
# "old" models are trained by a build of the commit before the fix (a git
# worktree sharing target-style, so only the workspace crates rebuild).
set -euo pipefail
cd "$(dirname "$0")/../.."
ROOT=$PWD
DATA=${MOCAP_SHARED_DATA:-../shared/data}/bandai
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-$ROOT/target-style}
WALKS=walk,walk-back,walk-left,walk-right,walk-turn-left,walk-turn-right
OUT=bench/style/out/mirror-fix
BEFORE=4dfcbca~1
mkdir -p "$OUT" /tmp/mocap-mirror-fix

if [ ! -x /tmp/mocap-mirror-fix/style_train_old ]; then
  rm -rf /tmp/mocap-mirror-fix/tree
  git worktree add -f --detach /tmp/mocap-mirror-fix/tree "$BEFORE"
  (cd /tmp/mocap-mirror-fix/tree && cargo build -q --profile test -p mocap-style --example style_train)
  cp "$CARGO_TARGET_DIR/debug/examples/style_train" /tmp/mocap-mirror-fix/style_train_old
  git worktree remove --force /tmp/mocap-mirror-fix/tree
fi
cargo build -q --profile test -p mocap-style --examples
BIN=$CARGO_TARGET_DIR/debug/examples

run() { # KIND SEED TRAINER
  local dir=$OUT/$1-seed$2
  mkdir -p "$dir"
  [ -f "$dir/style.safetensors" ] || "$3" --epochs 30 --steps 100 --seed "$2" --contents "$WALKS" \
    -o "$dir/style.safetensors" "$DATA/dataset-1" "$DATA/dataset-2" > "$dir/train.json" 2> "$dir/train.log"
  "$BIN/style_eval" --model "$dir/style.safetensors" --sources walk,walk-turn-left,walk-turn-right \
    --styles walk --classifier-contents "$WALKS" --json "$dir/eval.json" --markdown "$dir/eval.md" \
    "$DATA/dataset-1" "$DATA/dataset-2" > /dev/null 2> "$dir/eval.log"
}
for seed in 1 2 3; do
  run old "$seed" /tmp/mocap-mirror-fix/style_train_old
  run new "$seed" "$BIN/style_train"
done
python3 bench/style/seeds_table.py "$OUT" | tee "$OUT/seeds.md"
