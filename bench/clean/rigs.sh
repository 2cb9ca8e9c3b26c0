#!/usr/bin/env bash
# Reproduces bench/clean/rigs/ (bench/results/clean.md, "Other rigs"): the shipped denoiser on takes of other rigs,
# which it cleans through its own (Bandai) rig, against the cross-validated Butterworth on the take's own rig.
#
#   bash bench/clean/rigs.sh         # about 5 min on 2 CPU cores
#
# 1. Held-out Bandai motion on other rigs: 40 Bandai test takes on their own rig and played by the rigs of a CMU clip (Xia's
#    MotionBuilder names), a CMU-Daz clip, a FAIR clip, a Mixamo clip and the Kinect skeleton `mocap fuse` fits
#    (from the demo),
#    the evaluation's random noise put on there.
# 2. Real takes of other rigs, with the same noise (`mocap clean eval`): the CMU-Daz test split, and every take
#    of Xia, FAIR and CMU-3ds-Max (the filters are then tuned on those takes themselves, which flatters them).
# MOCAP=path/to/mocap and STUDY=path/to/clean_foreign_rig_eval run built binaries; MODEL=FILE evaluates another model
# in the shipped one's place, OUT=DIR writes elsewhere.
set -euo pipefail
cd "$(dirname "$0")/../.."
SHARED="${MOCAP_SHARED_DATA:-../shared/data}"
MOCAP=${MOCAP:-cargo run --release -q -p mocap-cli --}
STUDY=${STUDY:-cargo run --release -q -p mocap-studies --example clean_foreign_rig_eval --}
OUT=${OUT:-bench/clean/rigs}
mkdir -p "$OUT"
if [ -n "${MODEL:-}" ]; then export MOCAP_CLEAN_MODEL="$MODEL"; fi
$MOCAP -q demo -o "$OUT/demo" >/dev/null
cp "$OUT/demo/fuse/fused.bvh" "$OUT/kinect-fused.bvh"
rm -r "$OUT/demo"
R="$SHARED/other-rigs"
for rig in "bandai=samples/dataset-1_walk_normal_001.bvh" "cmu-xia=$R/xia/neutral_01_000.bvh" "cmu-daz=$R/cmu-daz/02/02_01.bvh" \
    "fair=$R/animated-drawings/fair1/dab.bvh" "mixamo=$SHARED/parser-cases/bvhpython_test_freebvh.bvh" \
    "kinect-fused=$OUT/kinect-fused.bvh"; do
    $STUDY "$SHARED/bandai" "${rig#*=}" 40 >"$OUT/bandai-on-${rig%%=*}.md"
done
EVAL=(--spike-lengths none --markdown)
$MOCAP -q clean eval "$R/cmu-daz" "${EVAL[@]}" "$OUT/real-cmu-daz.md" --json >"$OUT/real-cmu-daz.json"
for d in xia animated-drawings/fair1 cmu-max; do
    name=$(basename "$d")
    $MOCAP -q clean eval "$R/$d" --all-takes "${EVAL[@]}" "$OUT/real-$name.md" --json >"$OUT/real-$name.json"
done
