#!/usr/bin/env bash
# Reproduces bench/clean/foreign/ (bench/results/clean.md, "Known limits"): 40 Bandai test takes played by a
# CMU-style and a Mixamo rig, and resampled to 24, 60 and 120 fps, with the evaluation's random noise (about 2 min).
set -euo pipefail
cd "$(dirname "$0")/../.."
DATA="${MOCAP_SHARED_DATA:-../shared/data}/bandai"
P="${MOCAP_SHARED_DATA:-../shared/data}/parser-cases"
RUN="cargo run --release -q -p mocap-studies --example clean_foreign_rig_eval --"
OUT=bench/clean/foreign
mkdir -p "$OUT"
$RUN "$DATA" "$P/dme_example_crlf_leadingdot_frametime.bvh" 40 >"$OUT/rig-cmu.md"
$RUN "$DATA" "$P/bvhpython_test_freebvh.bvh" 40 >"$OUT/rig-mixamo.md"
for f in 24 60 120; do $RUN "$DATA" --fps $f 40 >"$OUT/fps-$f.md"; done
