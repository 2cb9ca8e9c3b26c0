#!/usr/bin/env bash
# Reproduces bench/clean/foreign/ (bench/results/clean.md, "Known limits"): 40 Bandai test takes resampled to 24,
# 60 and 120 fps, with the evaluation's random noise (about 1 min). Other rigs: bench/clean/rigs.sh.
set -euo pipefail
cd "$(dirname "$0")/../.."
DATA="${MOCAP_SHARED_DATA:-../shared/data}/bandai"
RUN="cargo run --release -q -p mocap-studies --example clean_foreign_rig_eval --"
OUT=bench/clean/foreign
mkdir -p "$OUT"
for f in 24 60 120; do $RUN "$DATA" --fps $f 40 >"$OUT/fps-$f.md"; done
