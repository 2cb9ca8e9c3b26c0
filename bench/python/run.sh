#!/usr/bin/env bash
# The Python package's speed (bench/results/python.md): m.positions() on a
# ten-minute take against the Rust FK of the same take, and mocap.read
# against bvhio on the Bandai files. A release wheel in its own venv.
# Needs the shared data (../shared/data or $MOCAP_SHARED_DATA).
set -euo pipefail
cd "$(dirname "$0")/../.."

target="${CARGO_TARGET_DIR:-target}"
data="${MOCAP_SHARED_DATA:-../shared/data}"
files=("$data"/bandai/dataset-1/*.bvh)
[ -f "${files[0]}" ] || { echo "no Bandai data at $data/bandai/dataset-1" >&2; exit 1; }

venv="$target/py-bench-venv"
[ -x "$venv/bin/python" ] || { mkdir -p "$target"; python3 -m venv "$venv"; }
venv="$(cd "$venv" && pwd)"
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check "maturin>=1.9.4,<2" numpy bvhio

echo "== release builds: the wheel and the Rust FK timing; the CLI (dev) to make the take"
rm -rf "$target/py-wheels-release"
"$venv/bin/maturin" build --quiet --release -m crates/mocap-py/Cargo.toml \
    --interpreter "$venv/bin/python" --out "$target/py-wheels-release"
"$venv/bin/python" -m pip uninstall --quiet --yes mocap 2>/dev/null || true
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check "$target"/py-wheels-release/mocap-*.whl
cargo build --quiet -p mocap-cli
cargo build --quiet --release -p mocap-py --example fk_timing

echo "== a ten-minute take: dataset-1's longest take looped to 18,000 frames or more"
# (Bandai's takes differ in their skeletons' offsets, so one take is looped:
# takes of different skeletons cannot be joined.)
long="$target/py-bench-long.bvh"
take_frames() { sed -n 's/^Frames:[[:space:]]*//p' "$1" | tr -d '\r'; }
longest="" most=0
for f in "${files[@]}"; do
    n=$(take_frames "$f")
    if [ "$n" -gt "$most" ]; then most=$n; longest=$f; fi
done
inputs=()
for _ in $(seq $(((18000 + most - 1) / most))); do inputs+=("$longest"); done
"$target/debug/mocap" -q convert "${inputs[@]}" "$long"

rust=$("$target/release/examples/fk_timing" "$long" 5)
echo "rust: $rust"
"$venv/bin/python" bench/python/bench.py "$long" "$rust" "bench/python/run.sh" "${files[@]}"
