#!/usr/bin/env bash
# All the tests, in one command (the README's test command; CI runs it):
#
# 1. the Rust tests of every crate (`cargo test --workspace`);
# 2. the Python package: wheel built with maturin, installed in a fresh
#    virtual environment, pytest (tests/python/run.sh);
# 3. glTF output in its real consumers: the Khronos validator and Blender's
#    importer (tests/gltf/run.sh);
# 4. the viewer in a real headless Chromium (tests/browser/run.sh).
#
#   bash tests/run.sh
#
# Steps 2-4 install what they need (PyPI, npm, Debian packages) when it is
# missing. Tests that need real data read ../shared/data (or
# $MOCAP_SHARED_DATA) and skip with a note when it is absent.
set -euo pipefail
cd "$(dirname "$0")/.."

echo "== Rust: cargo test --workspace"
cargo test --workspace
echo "== Python: tests/python/run.sh"
bash tests/python/run.sh
echo "== glTF consumers: tests/gltf/run.sh"
bash tests/gltf/run.sh
echo "== viewer in headless Chromium: tests/browser/run.sh"
bash tests/browser/run.sh
