#!/bin/bash
# Spike boundaries by summed evidence (session 26; bench/results/clean.md, "Spike boundaries by summed evidence"):
# the grid on the 120 validation takes (subtree_evidence, about 5 min), then the default finder against three
# settings over six draws of the evaluation's noise on the 116 test takes (about 11 min: one draw 1.9 min on the quiet machine).
# Binaries: cargo build --profile test -p mocap-clean --examples (or CARGO_TARGET_DIR=target-clean, BIN below)
set -e
cd "$(dirname "$0")/../.."
BIN=${BIN:-./target/debug/examples}
DATA=../shared/data/bandai
OUT=bench/clean/evidence
mkdir -p $OUT
$BIN/subtree_evidence $DATA 1000 > $OUT/validation.md
EVIDENCE_DRAWS=1 $BIN/subtree_evidence $DATA 7,8,9,10,11,12 > $OUT/draws.md
