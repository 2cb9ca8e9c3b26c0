#!/usr/bin/env bash
# Reproduces the evaluation tables of bench/results/clean.md into bench/clean/eval/ (116 Bandai test takes).
#
#   bash bench/clean/eval.sh         # about 40 min on 2 CPU cores
#
# The baselines include the network on the single Wiener filter and the Wiener mixture alone when
# bench/clean/model.sh has written them. MOCAP=path/to/mocap runs a built binary instead of
# `cargo run --release -p mocap-cli`.
set -euo pipefail
cd "$(dirname "$0")/../.."
DATA="${MOCAP_SHARED_DATA:-../shared/data}/bandai"
MOCAP=${MOCAP:-cargo run --release -q -p mocap-cli --}
STUDY="cargo run --release -q -p mocap-studies --example"
MODEL=bench/clean/model
OUT=bench/clean/eval
mkdir -p "$OUT"
SPIKES=(--spike-lengths 2,4,8,16,32,64)
# The noisy input, the classical filters (each tuned on 12 validation takes), the Wiener filters and the shipped
# model, under random noise, spikes on random noise and spikes alone, and the spike survival.
BASELINES=(--model "learned Wiener filter=models/clean-wiener.safetensors")
[ -f "$MODEL/wiener-mixture.safetensors" ] && BASELINES+=(--model "Wiener mixture alone=$MODEL/wiener-mixture.safetensors")
[ -f "$MODEL/network.safetensors" ] && BASELINES+=(--model "the shipped network on the single Wiener filter=$MODEL/network.safetensors")
$MOCAP -q clean eval "$DATA" --tune-takes 12 "${SPIKES[@]}" "${BASELINES[@]}" \
    --markdown "$OUT/baselines.md" --json >"$OUT/baselines.json"
# Takes with at most 2 degrees of random noise.
$MOCAP -q clean eval "$DATA" --no-filters --max-sigma 2 --spike-lengths none \
    --markdown "$OUT/low-noise.md" --json >"$OUT/low-noise.json"
# The shipped model with spike finding first (`mocap clean apply --despike`), its settings tuned on 12 validation takes.
$MOCAP -q clean eval "$DATA" --tune-takes 12 --no-filters --despike "${SPIKES[@]}" \
    --markdown "$OUT/despike.md" --json >"$OUT/despike.json"
# Six noise draws (seed 7 is the evaluation's own), clean takes and low noise, both level estimates (about 7 min).
$STUDY clean_level_estimate -- "$DATA" 7,8,9,10,11,12 >"$OUT/draws.md"
# The same draws with the best fixed Butterworth and the true spikes bridged (an oracle) (about 4 min).
$STUDY clean_spike_draws -- "$DATA" 7,8,9,10,11,12 >"$OUT/spike-draws.md"
# What spike finding misses, on the 120 validation takes (about 3 min).
$STUDY clean_spike_attribution -- "$DATA" 1000 >"$OUT/spike-misses.md"
