#!/usr/bin/env bash
# Reproduces bench/clean/fused/ (bench/results/clean.md, "Fused captures"): 40 Bandai test takes as the capture stage
# makes them (three simulated Kinect sensors, fused, fitted as a BVH) against their truth on the same skeleton, and the
# synthetic conditions beside (about 30 s on 2 CPU cores).
# MOCAP=path/to/mocap runs a built binary instead of `cargo run --release -p mocap-cli`.
set -euo pipefail
cd "$(dirname "$0")/../.."
DATA="${MOCAP_SHARED_DATA:-../shared/data}/bandai"
MOCAP=${MOCAP:-cargo run --release -q -p mocap-cli --}
OUT=bench/clean/fused
mkdir -p "$OUT"
$MOCAP -q clean eval "$DATA" --fused --spike-lengths none --max-takes 40 --tune-takes 12 \
    --markdown "$OUT/eval.md" --json >"$OUT/eval.json"
