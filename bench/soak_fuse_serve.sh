#!/usr/bin/env bash
# Soak test of the fusion server (not in CI): SENDERS simulated sensors at
# 30 Hz for SECONDS against `mocap fuse serve` (release build) on loopback,
# plus 1% bad datagrams (garbage, a time of 1e30 s, joints at 1e30 m). The
# server's resident memory is sampled every 5 s from /proc; its report must
# account for every datagram and lose no frame that arrived in time.
# Writes bench/results/soak.md.
#
# Usage: bench/soak_fuse_serve.sh [SECONDS=600] [SENDERS=8]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-600}
senders=${2:-8}
target=${CARGO_TARGET_DIR:-target}/release

cargo build --release -p mocap-cli
cargo build --release -p mocap-fuse --example soak_serve
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$target/mocap" fuse simulate samples/dataset-1_walk_normal_001.bvh \
    --sensors "$senders" --seed 1 -o "$work/sim" > /dev/null
command="bench/soak_fuse_serve.sh $seconds $senders"
set +e
"$target/examples/soak_serve" "$target/mocap" "$work/sim" "$senders" "$seconds" > "$work/soak.md"
status=$?
set -e
echo >> "$work/soak.md"
echo "Command: \`$command\` (release build, $(nproc) cores shared with other jobs, $(date -u +%Y-%m-%d))." >> "$work/soak.md"
mkdir -p bench/results
mv "$work/soak.md" bench/results/soak.md
cat bench/results/soak.md
exit $status
