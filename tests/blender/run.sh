#!/usr/bin/env bash
# Does every BVH that mocap writes import into Blender, with the joints where
# our forward kinematics puts them?
#
#   bash tests/blender/run.sh            # builds mocap (release) if needed
#   MOCAP=path/to/mocap bash tests/blender/run.sh
#
# Needs Blender (Debian/Ubuntu: `sudo apt-get install blender`; 3.4 on
# Debian 12). Without it the check prints a note and exits 0.
#
# Files checked: the bundled sample, an ASF/AMC take converted to BVH
# (`mocap convert`; HDM05 joints without degrees of freedom are written with
# `CHANNELS 0`), and the BVH outputs of `mocap demo` (fused, noisy, cleaned,
# restyled when the style model is there). For each, `mocap positions
# --json` gives our joint positions and tests/blender/check_import.py
# compares them with Blender's bone heads at a few frames (tolerance: 1e-3
# of body height). The per-file results are written to
# $OUT/blender-check.json (OUT defaults to a temporary folder) and printed.
# Real data comes from ../shared/data (or $MOCAP_SHARED_DATA); the HDM05
# take is skipped with a note when it is absent.
set -euo pipefail

ROOT="$(cd "$(dirname "$0")/../.." && pwd)"
if ! command -v blender >/dev/null 2>&1; then
    echo "note: blender is not installed (apt-get install blender); Blender import check skipped"
    exit 0
fi
DATA="${MOCAP_SHARED_DATA:-$ROOT/../shared/data}"
OUT="${OUT:-$(mktemp -d)}"
mkdir -p "$OUT"
if [ -z "${MOCAP:-}" ]; then
    (cd "$ROOT" && cargo build --release --quiet -p mocap-cli)
    MOCAP="${CARGO_TARGET_DIR:-$ROOT/target}/release/mocap"
fi

files=("$ROOT/samples/dataset-1_walk_normal_001.bvh")
if [ -f "$DATA/hdm05-sample/HDM_bd.asf" ]; then
    "$MOCAP" convert --quiet "$DATA/hdm05-sample/HDM_bd.asf" \
        "$DATA/hdm05-sample/HDM_bd_depositFloorR_001_120.amc" "$OUT/hdm05_converted.bvh"
    files+=("$OUT/hdm05_converted.bvh")
else
    echo "note: $DATA/hdm05-sample is absent; the ASF/AMC conversion is not checked"
fi
"$MOCAP" demo --quiet --no-pictures -o "$OUT/demo" > /dev/null
for f in fuse/fused.bvh fuse/truth.bvh clean/noisy.bvh clean/cleaned.bvh style/restyled.bvh; do
    if [ -f "$OUT/demo/$f" ]; then
        files+=("$OUT/demo/$f")
    else
        echo "note: the demo wrote no $f (see $OUT/demo/index.html); not checked"
    fi
done

pairs=()
for f in "${files[@]}"; do
    json="$OUT/$(basename "$f" .bvh).$(echo "$f" | cksum | cut -d' ' -f1).positions.json"
    "$MOCAP" positions --json -o "$json" "$f"
    pairs+=("$f" "$json")
done
blender --background --factory-startup --python-exit-code 1 \
    --python "$ROOT/tests/blender/check_import.py" -- "${pairs[@]}" \
    --report "$OUT/blender-check.json" 2>&1 | grep -E "^BLENDER-CHECK|Error|error" || true
# The script exits 1 on failure; grep above hides Blender's own chatter.
status=${PIPESTATUS[0]}
echo "results: $OUT/blender-check.json"
exit "$status"
