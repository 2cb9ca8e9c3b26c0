#!/bin/bash
# Quick evaluation of the shipped default model on 40 test takes.
set -e
cd "$(dirname "$0")/../.."
./target-clean/debug/examples/eval --data ../shared/data/bandai --max-takes 40 --tune-takes 12 \
  --json bench/clean/eval-quick.json --markdown bench/clean/eval-quick.md
