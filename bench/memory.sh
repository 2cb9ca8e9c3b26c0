#!/usr/bin/env bash
# Peak memory (max RSS) and wall time of every command that reads a take,
# on takes of about 10 MB, 100 MB and 1 GB (a Bandai take's frames repeated).
# Writes bench/results/memory-rows/LABEL.tsv and bench/results/memory.md.
#
# Usage: bench/memory.sh [LABEL [BINARY [OTHER_BINARY]]]   (default: after, the release build)
#   LABEL         the rows file: `before` for a build before a change, `after` for the current one
#   BINARY        the mocap binary to measure (default: cargo build --release -p mocap-cli)
#   OTHER_BINARY  also run every command on the 10 and 100 MB takes with this binary and
#                 compare the outputs byte for byte (e.g. the build before a change)
# Environment: SIZES (MB, default 10,100,1000), ONLY (commands whose name holds it),
#   LIMIT_GB (default 8: a run is stopped past it), LIMIT_S (default 1200),
#   MOCAP_SHARED_DATA (default ../shared/data).
# Needs /usr/bin/time (Debian: apt-get install time) and about 4 GB of disk for the 1 GB take.
set -euo pipefail
cd "$(dirname "$0")/.."
label=${1:-after}
binary=${2:-}
other=${3:-}
if [ -z "$binary" ]; then
    cargo build --release --quiet -p mocap-cli
    binary=${CARGO_TARGET_DIR:-target}/release/mocap
fi
[ -x /usr/bin/time ] || { echo "needs /usr/bin/time (apt-get install time)" >&2; exit 1; }
exec python3 bench/memory.py --mocap "$binary" --label "$label" \
    --sizes "${SIZES:-10,100,1000}" --only "${ONLY:-}" \
    --limit-gb "${LIMIT_GB:-8}" --limit-s "${LIMIT_S:-1200}" --same-as "$other" \
    --data "${MOCAP_SHARED_DATA:-../shared/data}/bandai/dataset-1" \
    --work "${CARGO_TARGET_DIR:-target}/memory-bench"
