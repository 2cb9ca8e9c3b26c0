#!/usr/bin/env bash
# glTF written by `mocap convert`, checked by the format's real consumers:
#
# 1. the Khronos glTF Validator (npm package gltf-validator): no errors;
# 2. Blender's own glTF importer (Debian's `blender`, headless): the right
#    bone count and frame range, bone heads at frames 0, middle and last
#    within 1 mm of our forward kinematics (tests/blender/check_gltf.py).
#
# The viewer's check of a .glb in headless Chromium is in tests/browser.
#
#   bash tests/gltf/run.sh               # from anywhere in the repository
#
# Installs what is missing (npm's gltf-validator under the target folder;
# Debian's blender with apt-get). Files checked: the bundled sample as .glb
# and .gltf; when ../shared/data (or $MOCAP_SHARED_DATA) is there, an
# HDM05 ASF/AMC take, a CMU take on the Daz naming, a 3ds Max CMU take and
# a Xia take. Reports go to $OUT (default: target/gltf-test/).
set -euo pipefail
cd "$(dirname "$0")/../.."
ROOT="$(pwd)"
TARGET_DIR="${CARGO_TARGET_DIR:-$ROOT/target}"
OUT_DIR="${OUT:-$TARGET_DIR/gltf-test}"
rm -rf "$OUT_DIR"
mkdir -p "$OUT_DIR"

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
# Blender's glTF importer needs numpy in Blender's Python (Debian's). Only
# what is missing is installed: a machine's Node.js may come from elsewhere
# (NodeSource's nodejs bundles npm, and Debian's npm conflicts with it).
packages=()
command -v blender >/dev/null 2>&1 || packages+=(blender)
/usr/bin/python3 -c "import numpy" >/dev/null 2>&1 || packages+=(python3-numpy)
command -v npm >/dev/null 2>&1 || packages+=(nodejs npm)
if [ ${#packages[@]} -gt 0 ]; then
    echo "== installing ${packages[*]} (Debian packages)"
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${packages[@]}" >/dev/null
fi
TOOLS="$TARGET_DIR/gltf-tools"
if [ ! -d "$TOOLS/node_modules/gltf-validator" ]; then
    echo "== installing gltf-validator (npm)"
    mkdir -p "$TOOLS"
    npm install --silent --no-audit --no-fund --prefix "$TOOLS" gltf-validator@2.0.0-dev.3.10 >/dev/null
fi

echo "== building mocap"
cargo build -q -p mocap-cli
MOCAP="$TARGET_DIR/debug/mocap"

DATA="${MOCAP_SHARED_DATA:-$ROOT/../shared/data}"
# name, then the input files of one take
takes=("sample|$ROOT/samples/dataset-1_walk_normal_001.bvh")
if [ -d "$DATA" ]; then
    takes+=("hdm05|$DATA/hdm05-sample/HDM_bd.asf|$DATA/hdm05-sample/HDM_bd_depositFloorR_001_120.amc")
    takes+=("cmu-daz|$DATA/other-rigs/cmu-daz/02/02_01.bvh")
    takes+=("cmu-max|$DATA/other-rigs/cmu-max/131_01.bvh")
    takes+=("xia|$DATA/other-rigs/xia/angry_13_000.bvh")
else
    echo "note: $DATA not found; checking the bundled sample only"
fi

gltfs=()
pairs=()
for take in "${takes[@]}"; do
    IFS='|' read -r name inputs <<< "$take"
    IFS='|' read -r -a files <<< "$inputs"
    missing=0
    for f in "${files[@]}"; do [ -f "$f" ] || missing=1; done
    if [ "$missing" = 1 ]; then
        echo "note: ${files[*]} not found; $name not checked"
        continue
    fi
    "$MOCAP" positions --json -o "$OUT_DIR/$name.positions.json" "${files[@]}"
    for ext in glb gltf; do
        "$MOCAP" convert "${files[@]}" "$OUT_DIR/$name.$ext"
        gltfs+=("$OUT_DIR/$name.$ext")
        pairs+=("$OUT_DIR/$name.$ext" "$OUT_DIR/$name.positions.json")
    done
done

echo "== Khronos glTF Validator"
NODE_PATH="$TOOLS/node_modules" node tests/gltf/validate.js "${gltfs[@]}" \
    --report "$OUT_DIR/validator.json"

echo "== Blender's glTF importer"
set +e
blender --background --factory-startup --python-exit-code 1 \
    --python tests/blender/check_gltf.py -- "${pairs[@]}" \
    --report "$OUT_DIR/blender-gltf.json" > "$OUT_DIR/blender.log" 2>&1
status=$?
set -e
grep -E "^BLENDER-GLTF|Error|error" "$OUT_DIR/blender.log" || true
echo "results: $OUT_DIR/validator.json, $OUT_DIR/blender-gltf.json"
exit "$status"
