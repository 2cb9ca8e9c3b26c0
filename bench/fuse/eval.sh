#!/usr/bin/env bash
# Reproduces bench/results/fuse.md, "Accuracy against ground truth": fusion of
# 22 Bandai takes (walk, run, dash, dance, kick, bow; the shared subset has one
# dance and one kick take) watched by 2, 3 and 4 simulated sensors, seeds 1-3.
# Writes bench/results/fuse-eval[-body][-limits].json; the Markdown tables go
# to ${MD_DIR:-/tmp/fuse-eval}.
#   bash bench/fuse/eval.sh                     # the simulator's true sensor poses
#   CALIB=body bash bench/fuse/eval.sh          # sensors calibrated from the body
#   LIMITS=../shared/data/hdm05-sample/HDM_bd.asf bash bench/fuse/eval.sh
#                                               # + methods with ASF joint ranges
#   MOCAP=path/to/mocap bash bench/fuse/eval.sh (default: cargo run --release -p mocap-cli)
set -euo pipefail
cd "$(dirname "$0")/../.."
D=${MOCAP_SHARED_DATA:-../shared/data}/bandai/dataset-1
MOCAP=${MOCAP:-cargo run --release -q -p mocap-cli --}
MD_DIR=${MD_DIR:-/tmp/fuse-eval}
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
mkdir -p "$MD_DIR"
SUFFIX=${CALIB:+-$CALIB}${LIMITS:+-limits}
$MOCAP fuse eval --sensors 2,3,4 --seeds 1,2,3 ${CALIB:+--calib $CALIB} ${LIMITS:+--limits $LIMITS} \
  --json --markdown "$MD_DIR/fuse-eval$SUFFIX.md" "${FILES[@]}" > bench/results/fuse-eval$SUFFIX.json
echo "tables: $MD_DIR/fuse-eval$SUFFIX.md"
