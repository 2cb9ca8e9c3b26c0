#!/usr/bin/env bash
# Browser test of `mocap view` (the mocap-view crate's viewer) in a real
# headless Chromium (run as `mocap view`): installs Debian's chromium and chromium-driver when they
# are missing, builds the viewer, and runs check_viewer.py on the bundled
# sample (as BVH and as the .glb `mocap convert` writes), a second Bandai
# take when the shared data is there, and a small
# synthetic fused capture with confidence (written by the script).
#
#   bash tests/browser/run.sh            # from anywhere in the repository
#
# The screenshot is kept in $OUT (default: target/browser-test/).
set -euo pipefail
cd "$(dirname "$0")/../.."

# Debian's Python, which has Debian's selenium (not a pyenv or venv python3).
PYTHON=/usr/bin/python3
if ! command -v chromium >/dev/null 2>&1 || ! command -v chromedriver >/dev/null 2>&1 \
    || ! "$PYTHON" -c "import selenium" >/dev/null 2>&1; then
    echo "== installing chromium, chromium-driver and python3-selenium (Debian packages)"
    SUDO=""
    if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq chromium chromium-driver python3 python3-selenium >/dev/null
fi

echo "== building mocap"
cargo build -q -p mocap-cli
TARGET_DIR="${CARGO_TARGET_DIR:-target}"
VIEWER="$TARGET_DIR/debug/mocap"

DATA="${MOCAP_SHARED_DATA:-../shared/data}"
FILES=(samples/dataset-1_walk_normal_001.bvh)
SECOND="$DATA/bandai/dataset-1/dataset-1_bow_active_001.bvh"
if [ -f "$SECOND" ]; then
    FILES+=("$SECOND")
else
    echo "note: $SECOND not found; testing with the bundled sample only"
fi

OUT_DIR="${OUT:-$TARGET_DIR/browser-test}"
mkdir -p "$OUT_DIR"
# The bundled sample as glTF (mocap convert), played from the .glb.
"$VIEWER" convert --quiet samples/dataset-1_walk_normal_001.bvh "$OUT_DIR/sample.glb"
FILES+=("$OUT_DIR/sample.glb")
echo "== headless Chromium"
"$PYTHON" tests/browser/check_viewer.py --viewer "$VIEWER" --out "$OUT_DIR" --with-fused \
    --chromium "$(command -v chromium)" --chromedriver "$(command -v chromedriver)" "${FILES[@]}"
