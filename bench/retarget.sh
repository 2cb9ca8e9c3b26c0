#!/bin/bash
# Retargeting real takes onto other rigs and back (bench/results/retarget.md).
set -e
cd "$(dirname "$0")/.."
cargo build --release -p mocap-core --example retarget_check
T=${CARGO_TARGET_DIR:-target}
P=../shared/data/parser-cases
{
  cat bench/retarget-header.md
  for d in dataset-1 dataset-2; do
    $T/release/examples/retarget_check ../shared/data/bandai/$d \
      $P/dme_example_crlf_leadingdot_frametime.bvh $P/bvhpython_test_freebvh.bvh $P/bvhanim_test_mocapbank.bvh
    echo
  done
  echo "## Foreign clips on the Bandai rig"
  echo
  cat bench/retarget-plausibility.md
  B=../shared/data/bandai
  $T/release/examples/retarget_check --plausibility samples/dataset-1_walk_normal_001.bvh \
    $B/dataset-1/dataset-1_walk_proud_001.bvh $B/dataset-1/dataset-1_walk_old_001.bvh \
    $B/dataset-2/dataset-2_walk_active_001.bvh $B/dataset-1/dataset-1_run_normal_001.bvh \
    $P/dme_example_crlf_leadingdot_frametime.bvh $P/bvhpython_test_freebvh.bvh $P/bvhanim_test_mocapbank.bvh
} > bench/results/retarget.md
