#!/bin/bash
# The demo's chain (fuse over UDP, clean, feet, search, style) on held-out
# Bandai dataset-1 takes: the error against each take after every stage, and
# every stage's time (bench/results/chain.md).
#
# Usage: bench/chain.sh [MAX_TAKES]
set -e
cd "$(dirname "$0")/.."
D=${MOCAP_SHARED_DATA:-../shared/data}
T=${CARGO_TARGET_DIR:-target}
cargo build --release -p mocap-demo --example chain_bench
W=$(mktemp)
trap 'rm -f "$W"' EXIT
{
  echo "# The whole chain on held-out takes"
  echo
  echo "Made by \`bench/chain.sh $*\` ($(date -u +%Y-%m-%d), $(git rev-parse --short HEAD), $(nproc) cores,"
  echo "load average $(cut -d' ' -f1 /proc/loadavg) at the start)."
  echo
  cat bench/chain-header.md
  echo
  "$T/release/examples/chain_bench" "$D/bandai/dataset-1" "$@"
  cat bench/chain-summary.md
} > "$W"
cp "$W" bench/results/chain.md
echo "wrote bench/results/chain.md"
