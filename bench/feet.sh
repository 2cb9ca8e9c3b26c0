#!/bin/bash
# The feet stage (mocap-feet) on real clips, dragged and wobbled real walks,
# other rigs and restyled outputs: planted-foot sliding, feet below the
# floor and jitter before and after (bench/results/feet.md).
#
# Restyled outputs come from `mocap style apply` with the shipped model:
# MOCAP_BIN names the release binary (default: this workspace's, built here).
set -e
cd "$(dirname "$0")/.."
D=${MOCAP_SHARED_DATA:-../shared/data}
T=${CARGO_TARGET_DIR:-target}
cargo build --release -p mocap-feet --example feet_bench
if [ -z "$MOCAP_BIN" ]; then
  cargo build --release -p mocap-cli
  MOCAP_BIN=$T/release/mocap
fi
BENCH=$T/release/examples/feet_bench
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT

# Held-out Bandai dataset-2 walks: the last take of every (content, style)
# of the walk contents, as mocap-style's evaluation holds them out.
mkdir -p "$W/heldout" "$W/walk" "$W/restyled"
ls "$D/bandai/dataset-2" | grep -E '^dataset-2_walk[^_]*_.*\.bvh$' | python3 -c '
import sys, collections
groups = collections.defaultdict(list)
for name in map(str.strip, sys.stdin):
    parts = name[:-4].split("_")
    groups[(parts[1], parts[2])].append(name)
for takes in groups.values():
    if len(takes) >= 2:
        print(max(takes))
' | sort | while read -r f; do
  ln -s "$(realpath "$D/bandai/dataset-2/$f")" "$W/heldout/$f"
  case $f in dataset-2_walk_*) ln -s "$(realpath "$D/bandai/dataset-2/$f")" "$W/walk/$f";; esac
done

# Restyled: every held-out straight walk given every other one's style.
for src in "$W"/walk/*.bvh; do
  for sty in "$W"/walk/*.bvh; do
    [ "$src" = "$sty" ] && continue
    s=$(basename "$src" .bvh | cut -d_ -f3); t=$(basename "$sty" .bvh | cut -d_ -f3)
    "$MOCAP_BIN" -q style apply "$src" --style "$sty" -o "$W/restyled/${s}-as-${t}.bvh"
  done
done

section() { echo; echo "## $1"; echo; echo "\`$2\`"; echo; }
{
  echo "# Feet that stay planted (mocap-feet)"
  echo
  echo "Made by \`bench/feet.sh\` ($(date -u +%Y-%m-%d), $(git rev-parse --short HEAD)). Sliding and"
  echo "depths in % of the rig's leg length (hip to ankle; Bandai's is 80 cm, so 1% leg/s is"
  echo "0.8 cm/s); jitter is the mean jerk of all joints (units/frame³), before → after."
  echo
  cat bench/feet-summary.md
  section "Held-out Bandai dataset-2 walks, as captured" "feet_bench <held-out walks>"
  $BENCH "$W/heldout"
  section "The same walks, root dragged sideways at 0.5 leg/s (40 cm/s)" "feet_bench --drag 0.5 <held-out walks>"
  $BENCH --drag 0.5 "$W/heldout"
  section "The same walks, root wobbled sideways by 0.08 leg (6 cm) at 2 Hz" "feet_bench --wobble 0.08 <held-out walks>"
  $BENCH --wobble 0.08 "$W/heldout"
  section "Restyled held-out walks (mocap style apply, shipped model, every source × style)" "feet_bench <restyled>"
  $BENCH "$W/restyled"
  section "Other rigs (other-rigs, parser-cases, HDM05)" "feet_bench <clips>"
  $BENCH "$D/other-rigs/xia" "$D/other-rigs/cmu-max" "$D/other-rigs/cmu-asf" \
    "$D/other-rigs/animated-drawings" "$D/other-rigs/cmu-daz/02" "$D/other-rigs/cmu-daz/07" \
    "$D/parser-cases" "$D/hdm05-sample"
} > "$W/feet.md"
cp "$W/feet.md" bench/results/feet.md
echo "wrote bench/results/feet.md"
