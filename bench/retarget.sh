#!/bin/bash
# Retargeting real takes onto other rigs and back (bench/results/retarget.md).
set -e
cd "$(dirname "$0")/.."
cargo build --release -p mocap-core --example retarget_check
P=../shared/data/parser-cases
{
  cat bench/retarget-header.md
  for d in dataset-1 dataset-2; do
    ./target/release/examples/retarget_check ../shared/data/bandai/$d \
      $P/dme_example_crlf_leadingdot_frametime.bvh $P/bvhpython_test_freebvh.bvh $P/bvhanim_test_mocapbank.bvh
    echo
  done
} > bench/results/retarget.md
