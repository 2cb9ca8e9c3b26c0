#!/usr/bin/env bash
# Reproduces bench/results/fuse.md, "Without ground truth": bone-length
# consistency of single sensors against the fused skeleton on NTU RGB+D style
# .skeleton files, sensors calibrated from the body. No real NTU file is at
# hand, so the files are written by `mocap fuse simulate --ntu` from six Bandai
# takes (3 sensors each); with real NTU captures, give their files (C001, C002,
# C003 of a take) to `mocap fuse eval` the same way. Writes
# bench/results/fuse-ntu-consistency.json; the files and the Markdown tables
# stay in a temporary folder (printed).
#   MOCAP=path/to/mocap bash bench/fuse/ntu.sh   (default: cargo run --release -p mocap-cli)
set -euo pipefail
cd "$(dirname "$0")/../.."
D=${MOCAP_SHARED_DATA:-../shared/data}/bandai/dataset-1
MOCAP=${MOCAP:-cargo run --release -q -p mocap-cli --}
OUT=$(mktemp -d)
i=0
for c in walk_normal_001 run_normal_001 dance-short_normal_001 kick_normal_001 bow_normal_001 walk_happy_001; do
  i=$((i + 1))
  $MOCAP fuse simulate "$D/dataset-1_$c.bvh" --sensors 3 --seed $i --ntu -o "$OUT/$c" > /dev/null
  for f in "$OUT/$c"/S001C00*P001R001A001.skeleton; do
    b=$(basename "$f")
    mv "$f" "$OUT/${b/A001/A$(printf %03d $i)}"
  done
done
$MOCAP fuse eval "$OUT"/*.skeleton --json --markdown "$OUT/fuse-ntu-consistency.md" \
  > bench/results/fuse-ntu-consistency.json
echo "takes: A001..A006 = walk_normal, run_normal, dance-short, kick, bow_normal, walk_happy (files and tables in $OUT)"
