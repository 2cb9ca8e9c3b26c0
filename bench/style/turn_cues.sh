#!/usr/bin/env bash
# Why restyled dataset-2 turns were read as straight walks (bench/results/style.md,
# "The other fold" and "Turns kept"): the six right turns of the shipped fold that
# the active walk (dataset-2_walk_active_031) made into "walks" before session 16,
# restyled again with the shipped model and `mocap style apply` (elastic patches,
# as the evaluation), with the source's left-right asymmetry kept (the default)
# and without it (`--asymmetry style`, the report's method), then placed between
# real straight walks and real right turns on the pose values that tell those
# apart most (example feature_contrast); the sources the same way. Then the
# feet's sideways offset split into its slow change along the clip and the
# swing within each stride (example turn_swing), for real walks and turns,
# the sources and the outputs of every asymmetry setting. About a minute.
# Output: bench/style/out/turn-cues.md.
source "$(dirname "$0")/setup.sh"
cargo build -q --profile test -p mocap-cli
MOCAP=$CARGO_TARGET_DIR/debug/mocap
D2=$DATA/dataset-2
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
SOURCES=()
mkdir -p "$TMP/source" "$TMP/style"
for take in active_040 elderly_028 exhausted_037 feminine_031 normal_034 youthful_028; do
  SOURCES+=("$D2/dataset-2_walk-turn-right_$take.bvh")
  for asymmetry in source style; do
    "$MOCAP" style apply "$D2/dataset-2_walk-turn-right_$take.bvh" --asymmetry "$asymmetry" \
      --style "$D2/dataset-2_walk_active_031.bvh" -o "$TMP/$asymmetry/$take.bvh" -q
  done
done
{
  echo "## Outputs (six right turns restyled with dataset-2_walk_active_031)"
  echo
  "$BIN/feature_contrast" "$D2" walk-turn-right walk "$TMP"/source/*.bvh --top 10
  echo
  echo "## The same without the source's asymmetry (--asymmetry style, the report's method)"
  echo
  "$BIN/feature_contrast" "$D2" walk-turn-right walk "$TMP"/style/*.bvh --top 10
  echo
  echo "## Their sources"
  echo
  "$BIN/feature_contrast" "$D2" walk-turn-right walk "${SOURCES[@]}" --top 10
  echo
  echo "## The feet's sideways offset: its slow change along the clip, and the swing within a stride"
  echo
  "$BIN/turn_swing" "$D2" "$D2/dataset-2_walk_active_031.bvh" "${SOURCES[@]}"
} > "$OUT/turn-cues.md"
