#!/bin/bash
# The shipped denoiser on takes it was not made for (bench/results/clean.md, "Takes of other rigs and
# frame rates"): 40 held-out Bandai test takes played by a CMU-style and a Mixamo rig, and resampled to
# 24, 60 and 120 fps, with the evaluation's random noise. About 2 min.
# Binary: CARGO_TARGET_DIR=target-clean cargo build --profile test -p mocap-clean --examples
set -e
cd "$(dirname "$0")/../.."
BIN=./target-clean/debug/examples/foreign_rig_eval
DATA=../shared/data/bandai
P=../shared/data/parser-cases
OUT=bench/clean/foreign
mkdir -p $OUT
$BIN $DATA $P/dme_example_crlf_leadingdot_frametime.bvh 40 > $OUT/rig-cmu.md
$BIN $DATA $P/bvhpython_test_freebvh.bvh 40 > $OUT/rig-mixamo.md
for f in 24 60 120; do $BIN $DATA --fps $f 40 > $OUT/fps-$f.md; done
