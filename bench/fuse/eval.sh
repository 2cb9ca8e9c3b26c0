#!/usr/bin/env bash
# Fusion evaluation on real Bandai takes (walk, run, dash, dance, kick,
# bow: 22 clips; the subset has one dance and one kick take), 2, 3 and 4 sensors, 3 seeds. Writes bench/results/fuse-eval.md and
# bench/results/fuse-eval.json. Until `mocap fuse eval` is wired into the CLI
# this runs the example of the same code.
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
${FUSE_EVAL:-cargo run --release -q -p mocap-fuse --example fuse_eval --} \
  --sensors 2,3,4 --seeds 1,2,3 ${CALIB:+--calib $CALIB} \
  --json bench/results/fuse-eval${CALIB:+-$CALIB}.json --md bench/results/fuse-eval${CALIB:+-$CALIB}.md "${FILES[@]}"
