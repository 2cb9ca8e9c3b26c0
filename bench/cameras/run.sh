#!/usr/bin/env bash
# Reproduces bench/results/cameras.md: the triangulation methods of
# `mocap cameras` on the real Pose2Sim demo capture (four cameras, OpenPose
# BODY_25B) against Pose2Sim's own triangulation, and on Bandai takes filmed
# by simulated cameras against their truth. Writes bench/cameras/results/.
#   MOCAP=path/to/mocap bash bench/cameras/run.sh   (default: cargo run --release -p mocap-cli)
set -euo pipefail
cd "$(dirname "$0")/../.."
DATA=${MOCAP_SHARED_DATA:-../shared/data}
MOCAP=${MOCAP:-cargo run --release -q -p mocap-cli --}
OUT=bench/cameras/results
mkdir -p "$OUT"
P2S=$DATA/pose2sim-demo

# 1. The real capture, against Pose2Sim's triangulation of the same keypoints
# (its raw TRC, before filtering). `pose-associated` holds the person Pose2Sim
# chose in each view; `pose` the raw OpenPose output, where mocap finds the
# person itself.
for folder in pose-associated pose; do
  trial=S00_P00_SingleParticipant/S00_P00_T01_BalancingTrial
  $MOCAP cameras eval "$P2S/$trial/$folder" --reference "$P2S/$trial/pose-3d/S00_P00_T01_BalancingTrial_0-100.trc" \
    --json --markdown "$OUT/pose2sim-balancing-$folder.md" > "$OUT/pose2sim-balancing-$folder.json"
done
# The two-person trial, raw OpenPose output: each person mocap finds against
# each of Pose2Sim's two (the summary pairs them by distance).
MULTI=$P2S/S00_P01_MultiParticipants/S00_P01_T02_Participants1-2
for person in 1 2; do
  for theirs in P1 P2; do
    $MOCAP cameras eval "$MULTI/pose" --person $person \
      --reference "$MULTI/pose-3d/S00_P01_T02_Participants1-2_${theirs}_0-100.trc" \
      --json > "$OUT/multi-person$person-$theirs.json"
  done
done
tmp=$(mktemp -d)

# 2. Simulated cameras on Bandai takes (one take of each of ten contents).
for take in walk_normal_001 run_normal_001 dance-short_normal_001 kick_normal_001 bow_normal_001 \
            punch_normal_001 slash_normal_001 walk-back_normal_001 \
            byebye_normal_001 dash_normal_001; do
  f=$DATA/bandai/dataset-1/dataset-1_$take.bvh
  [ -f "$f" ] || { echo "missing $f" >&2; continue; }
  rm -rf "$tmp/$take"
  $MOCAP cameras simulate "$f" -o "$tmp/$take" --seed 7
  $MOCAP cameras eval "$tmp/$take" --truth "$tmp/$take/truth.trc" \
    --json --markdown "$OUT/sim-$take.md" > "$OUT/sim-$take.json"
done
python3 bench/cameras/summary.py "$OUT" > "$OUT/summary.md"
cat "$OUT/summary.md"
echo "(simulated trials in $tmp)"
