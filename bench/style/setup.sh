# Sourced by the style benchmark scripts (run.sh, judges.sh): the data, the
# test-profile build of mocap-style's examples and where they are.
#
# Build profile: `--profile test` (dependencies at opt-level 2 from the dev
# profile, the workspace crates at opt-level 1), because a release build of
# burn takes about half an hour on the 2-core machine. Speed figures are for
# that build.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
DATA=${MOCAP_SHARED_DATA:-../shared/data}/bandai
# target-style holds the test-profile builds of this crate (shared machine:
# one build directory for this benchmark, not a second copy of burn).
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-target-style}
cargo build -q --profile test -p mocap-style --examples
BIN=$CARGO_TARGET_DIR/debug/examples
WALKS=walk,walk-back,walk-left,walk-right,walk-turn-left,walk-turn-right
OUT=bench/style/out
mkdir -p "$OUT"
# The other fold's model (the first take of each group held out), which
# `run.sh --other-fold` trains and judges.sh and asymmetry.sh read.
FOLD_MODEL=${MODEL_DIR:-/tmp}/style-fold-first.safetensors
require_fold_model() {
  if [[ ! -f "$FOLD_MODEL" ]]; then
    echo "needs the other fold's model $FOLD_MODEL: run bash bench/style/run.sh --other-fold first" >&2
    exit 1
  fi
}
