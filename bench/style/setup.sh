# Sourced by the style benchmark scripts: the data, the test-profile builds of
# the CLI, the style studies and the speed benchmark, and where they are.
#
# Build profile: `--profile test` (dependencies at opt-level 2 from the dev
# profile, the workspace crates at opt-level 1), because a release build of
# burn takes about half an hour on a 2-core machine. Speed figures are for
# that build.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
DATA=${MOCAP_SHARED_DATA:-../shared/data}/bandai
# One build directory for these scripts (not a second copy of burn in target/).
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-target-style}
build() {
  # The CLI and the examples carry the shipped model inside them
  # (include_bytes!), so they are rebuilt after `run.sh --train`.
  cargo build -q --profile test -p mocap-cli --bin mocap
  cargo build -q --profile test -p mocap-studies --example style_classifiers \
    --example style_familiarity --example style_foot_cleanup --example style_asymmetry_along \
    --example style_feature_contrast --example style_turn_swing
  cargo build -q --profile test -p mocap-style --example style_speed
}
build
MOCAP=$CARGO_TARGET_DIR/debug/mocap
BIN=$CARGO_TARGET_DIR/debug/examples
WALKS=walk,walk-back,walk-left,walk-right,walk-turn-left,walk-turn-right
# The evaluation's pairs and judges, as in bench/results/style.md.
PAIRS=(--sources walk,walk-turn-left,walk-turn-right --styles walk --classifier-contents "$WALKS")
OUT=bench/style/out
mkdir -p "$OUT"
# The other fold's model (the first take of each group held out), which
# `run.sh --other-fold` trains and judges.sh, asymmetry.sh, patch_judges.sh
# and patch_select.sh read.
FOLD_MODEL=${MODEL_DIR:-/tmp}/style-fold-first.safetensors
require_fold_model() {
  if [[ ! -f "$FOLD_MODEL" ]]; then
    echo "needs the other fold's model $FOLD_MODEL: run bash bench/style/run.sh --other-fold first" >&2
    exit 1
  fi
}
