#!/usr/bin/env bash
# Fusion evaluation on real Bandai takes (walk, run, dash, dance, kick,
# bow: 22 clips; the subset has one dance and one kick take), 2, 3 and 4
# sensors, 3 seeds. Writes bench/results/fuse-eval[-body][-limits].md and
# .json. Runs the crate's example `fuse_eval`, the same code as
# `mocap fuse eval` (which would build the whole CLI first):
#   CALIB=body bash bench/fuse/eval.sh          # sensors calibrated from the body
#   LIMITS=../shared/data/hdm05-sample/HDM_bd.asf bash bench/fuse/eval.sh
#                                               # + methods with ASF joint ranges
set -euo pipefail
cd "$(dirname "$0")/../.."
D=${MOCAP_SHARED_DATA:-../shared/data}/bandai/dataset-1
CLIPS=(
  walk_normal_001 walk_active_001 walk_happy_001 walk_proud_001 walk_tired_001 walk_old_001
  run_normal_001 run_active_001 run_childish_001 run_tired_001 run_proud_001
  walk_sad_001 run_sad_001
  dance-short_normal_001 kick_normal_001
  bow_normal_001 bow_active_001 bow_proud_001 bow_tired_001 bow_old_001 bow_happy_001
  dash_normal_001
)
FILES=()
for c in "${CLIPS[@]}"; do
  f=$(ls "$D"/dataset-1_${c}.bvh 2>/dev/null || true)
  [ -n "$f" ] || { echo "missing $D/dataset-1_${c}.bvh" >&2; exit 1; }
  FILES+=("$f")
done
SUFFIX=${CALIB:+-$CALIB}${LIMITS:+-limits}
${FUSE_EVAL:-cargo run --release -q -p mocap-fuse --example fuse_eval --} \
  --sensors 2,3,4 --seeds 1,2,3 ${CALIB:+--calib $CALIB} ${LIMITS:+--limits $LIMITS} \
  --json bench/results/fuse-eval$SUFFIX.json --md bench/results/fuse-eval$SUFFIX.md "${FILES[@]}"
