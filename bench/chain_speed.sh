#!/bin/bash
# The whole chain on a 10-second take, as a user runs it from the command
# line (fuse offline, clean, feet, search, restyle): wall seconds of each
# command, and `mocap info` on the same take beside them as the floor every
# command pays (starting the process and reading a take).
#
# Usage: bench/chain_speed.sh [RUNS]   (default 5; the median is reported)
# Writes bench/results/chain-speed.md. Needs ../shared/data (or
# $MOCAP_SHARED_DATA): the take is the first 300 frames (10 s) of Bandai's
# dataset-1_dance-short_normal_001, watched by 3 simulated Kinect v2 sensors.
set -euo pipefail
cd "$(dirname "$0")/.."
RUNS=${1:-5}
D=${MOCAP_SHARED_DATA:-../shared/data}
T=${CARGO_TARGET_DIR:-target}
cargo build --release -q -p mocap-cli
M="$T/release/mocap"
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT

"$M" convert -q "$D/bandai/dataset-1/dataset-1_dance-short_normal_001.bvh" --frames 0..300 "$W/take.bvh"
"$M" fuse simulate -q "$W/take.bvh" --sensors 3 --seed 1 -o "$W/sim" > /dev/null
STYLE=samples/dataset-1_walk_proud_001.bvh
INDEX=models/search-bandai-content.idx

# name|command (run by bash -c, in $W)
stages=(
  "floor: mocap info|$M info take.bvh"
  "fuse run (offline, 3 sensors)|$M fuse run sim/sensor-0.jsonl sim/sensor-1.jsonl sim/sensor-2.jsonl --calib sim/truth.calib.toml -o fused.bvh -q"
  "clean apply (shipped model)|$M clean apply fused.bvh -o cleaned.bvh -q"
  "feet|$M feet cleaned.bvh -o feet.bvh -q"
  "search query (bundled index)|$M search query --index $PWD/$INDEX feet.bvh -q"
  "style apply (proud walk)|$M style apply feet.bvh --style $PWD/$STYLE -o styled.bvh -q"
)

median() { sort -n | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }

rows=""
total=0
for stage in "${stages[@]}"; do
  name=${stage%%|*}
  command=${stage#*|}
  times=""
  for _ in $(seq "$RUNS"); do
    start=$(date +%s.%N)
    (cd "$W" && bash -c "$command" > /dev/null)
    times+="$(echo "$(date +%s.%N) - $start" | bc)"$'\n'
  done
  m=$(printf "%s" "$times" | median)
  rows+="| $name | $(printf %.3f "$m") |"$'\n'
  if [[ $name != floor* ]]; then total=$(echo "$total + $m" | bc); fi
done

{
  echo "# The chain's speed on a 10-second take"
  echo
  echo "Made by \`bench/chain_speed.sh $RUNS\` ($(date -u +%Y-%m-%d), $(git rev-parse --short HEAD), $(nproc) cores,"
  echo "load average $(cut -d' ' -f1 /proc/loadavg) at the end). The median of $RUNS runs of each command."
  echo
  echo "The take: the first 300 frames (10.0 s at 30 fps) of Bandai's \`dataset-1_dance-short_normal_001\`,"
  echo "watched by 3 simulated Kinect v2 sensors (\`mocap fuse simulate --seed 1\`). Each stage is one"
  echo "\`mocap\` command reading the previous stage's file, as a user runs the chain; \`mocap info\` on the"
  echo "same take is the floor every command pays (starting the process, reading a take)."
  echo
  echo "| command | seconds |"
  echo "| --- | --- |"
  printf "%s" "$rows"
  echo "| **the chain (fuse to style)** | **$(printf %.3f "$total")** |"
} > bench/results/chain-speed.md
cat bench/results/chain-speed.md
