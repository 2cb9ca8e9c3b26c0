#!/bin/bash
# What spike finding could give at best (bench/results/clean.md, "Spikes: what finding them could give"): on 40
# validation takes with random noise of fixed sigma (0, 2, 5, 10 degrees, then drawn in 0-10) and 1-3 spikes, the
# true spikes bridged before the shipped Wiener filter, or marked missing for it (estimated from the rest of the
# body), against the filter reading them and the same takes without spikes; the same with the shipped model, and the spikes
# that spike finding finds after it bridged in its output or in the input before a second run. About a minute here.
set -e
cd "$(dirname "$0")/../.."
CARGO_TARGET_DIR=target-clean cargo build --profile test -p mocap-clean --examples
mkdir -p bench/clean/spikes
./target-clean/debug/examples/spike_oracle ../shared/data/bandai 40 0,2,5,10 > bench/clean/spikes/oracle.md
