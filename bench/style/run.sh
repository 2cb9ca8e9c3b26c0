#!/usr/bin/env bash
# Style transfer benchmark (issue 6): evaluation on held-out Bandai takes and
# the time to restyle a 10-second clip. Results: bench/results/style.md.
#
#   bash bench/style/run.sh            # eval + speed with the shipped model
#   bash bench/style/run.sh --train    # retrain models/style-default.safetensors first
#
# Build profile: `--profile test` (dependencies at opt-level 2 from the dev
# profile, the workspace crates at opt-level 1), because a release build of
# burn takes about half an hour on the 2-core machine. Speed figures are for
# that build.
set -euo pipefail
cd "$(dirname "$0")/../.."
DATA=${MOCAP_SHARED_DATA:-../shared/data}/bandai
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-target}
cargo build -q --profile test -p mocap-style --examples
BIN=$CARGO_TARGET_DIR/debug/examples
WALKS=walk,walk-back,walk-left,walk-right,walk-turn-left,walk-turn-right
OUT=bench/style/out
mkdir -p "$OUT"

if [[ "${1:-}" == "--train" ]]; then
  # The shipped default: the report's setting (240-frame windows, batch 16,
  # Adam, lr 1e-4), walking takes of both sets without the held-out takes,
  # with mirrored copies, seed 1.
  "$BIN/train" --epochs 30 --steps 100 --seed 1 --contents "$WALKS" \
    -o models/style-default.safetensors "$DATA/dataset-1" "$DATA/dataset-2" > "$OUT/train.json"
  cp models/style-default.png bench/style/loss.png
  # The loss plot goes to bench/style; the resumable state is not shipped.
  rm -rf models/style-default.png models/style-default.state
fi

"$BIN/eval" --sources walk,walk-turn-left,walk-turn-right --styles walk \
  --classifier-contents "$WALKS" --filmstrips bench/style/filmstrips \
  --json "$OUT/eval.json" --markdown "$OUT/eval.md" "$DATA/dataset-1" "$DATA/dataset-2"

"$BIN/speed" "$DATA/dataset-1/dataset-1_walk_not-confident_001.bvh" \
  "$DATA/dataset-1/dataset-1_walk_proud_002.bvh" --runs 20 | tee "$OUT/speed.md"
