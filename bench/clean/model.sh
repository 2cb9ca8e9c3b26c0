#!/usr/bin/env bash
# Reproduces the shipped models (bench/results/clean.md, "The method measured"): models/clean-wiener.safetensors,
# the network trained on it, and models/clean-default.safetensors, that network on a mixture of its filter.
#
#   bash bench/clean/model.sh        # about 1 hour on 2 CPU cores (the network: 45 min)
#
# Writes models/clean-wiener.safetensors, models/clean-default.safetensors and models/clean-default.json (its
# header: description, data, training record), and under bench/clean/model/ (not kept in git) the network on the
# single Wiener filter and the Wiener mixture alone, which bench/clean/eval.sh evaluates as baselines.
# MOCAP=path/to/mocap runs a built binary instead of `cargo run --release -p mocap-cli`.
set -euo pipefail
cd "$(dirname "$0")/../.."
DATA="${MOCAP_SHARED_DATA:-../shared/data}/bandai"
MOCAP=${MOCAP:-cargo run --release -q -p mocap-cli --}
OUT=bench/clean/model
mkdir -p "$OUT"
# The learned multichannel Wiener filter: spectra of the 929 training takes, 32-frame segments (about 70 s).
$MOCAP clean fit-wiener "$DATA" -o models/clean-wiener.safetensors
# The network reading and correcting it: width 64, 32-frame windows (models/clean-recipe.toml), the filter run on
# 128 frames each side of a window, its output and noise level as inputs, 12 epochs x 40 steps x 256 windows,
# derivative loss, lr 1e-3, seed 1 (45 min).
$MOCAP clean train "$DATA" --recipe models/clean-recipe.toml \
    --base-wiener models/clean-wiener.safetensors --base-context 128 --base-input \
    --epochs 12 --steps 40 --batch 256 --lr 1e-3 --seed 1 --plot "$OUT/network.png" -o "$OUT/network.safetensors"
# That network, not retrained, on a mixture of its own filter: one set of spectra per content with at least 150
# training segments, one for the rest, one for all (4-6 min).
$MOCAP clean fit-wiener "$DATA" --mixture 150 --rebase "$OUT/network.safetensors" -o models/clean-default.safetensors
python3 bench/clean/model_header.py models/clean-default.safetensors > models/clean-default.json
# The mixture alone, a baseline (4-6 min).
$MOCAP clean fit-wiener "$DATA" --mixture 150 -o "$OUT/wiener-mixture.safetensors"
