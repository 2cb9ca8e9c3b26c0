#!/usr/bin/env bash
# Reproduces bench/style/out/turn-cues.md (bench/results/style.md, "Turns kept
# along the take"): six dataset-2 right turns restyled with the active walk
# (dataset-2_walk_active_031) by `mocap style apply`, with the source's
# left-right asymmetry kept (the default) and without it (`--asymmetry style`,
# the report's method), placed between real straight walks and real right turns
# on the pose values that tell those apart most (study style_feature_contrast),
# their sources the same way; then the feet's sideways offset split into its
# slow change along the clip and the swing within each stride (study
# style_turn_swing). About a minute.
source "$(dirname "$0")/setup.sh"
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
  "$BIN/style_feature_contrast" "$D2" walk-turn-right walk "$TMP"/source/*.bvh --top 10
  echo
  echo "## The same without the source's asymmetry (--asymmetry style, the report's method)"
  echo
  "$BIN/style_feature_contrast" "$D2" walk-turn-right walk "$TMP"/style/*.bvh --top 10
  echo
  echo "## Their sources"
  echo
  "$BIN/style_feature_contrast" "$D2" walk-turn-right walk "${SOURCES[@]}" --top 10
  echo
  echo "## The feet's sideways offset: its slow change along the clip, and the swing within a stride"
  echo
  "$BIN/style_turn_swing" "$D2" "$D2/dataset-2_walk_active_031.bvh" "${SOURCES[@]}"
} > "$OUT/turn-cues.md"
