#!/usr/bin/env bash
# Reproduces the fold-seed table of bench/results/search.md (bench/search/out/seeds.md), one row per call: the
# forest's mean accuracy and macro F over 5-fold cross-validations by take with fold seeds 1..S.
#
#   bash bench/search/seeds.sh PATTERN FOLDER [SEEDS] [-- extra `mocap search eval` options]
#
# Prints one Markdown table row: seeds, mean accuracy, mean macro F over all classes, mean macro F over classes
# with >= 10 clips, and the lowest and highest F over all classes. MOCAP=path/to/mocap runs a built binary.
set -euo pipefail
cd "$(dirname "$0")/../.."
pattern=$1 folder=$2 seeds=${3:-20}
shift $(($# >= 3 ? 3 : 2))
[ "${1:-}" = "--" ] && shift
MOCAP=${MOCAP:-cargo run --release -q -p mocap-cli --}
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT
for s in $(seq 1 "$seeds"); do
    $MOCAP -q search eval --labels-from-name "$pattern" --folds 5 --seed "$s" --no-baselines \
        --no-unseen --no-takes --json "$@" "$folder" >"$TMP/$s.json"
done
python3 - "$TMP" "$seeds" <<'PY'
import json, statistics, sys
folder, seeds = sys.argv[1], int(sys.argv[2])
acc, f_all, f_big = [], [], []
for s in range(1, seeds + 1):
    forest = json.load(open(f"{folder}/{s}.json"))["methods"][0]
    acc.append(forest["accuracy"])
    f_all.append(forest["average"]["f_measure"])
    # Classes with at least 10 test clips (all clips, in 5-fold CV).
    big = [c["f_measure"] for c in forest["per_class"] if c["support"] >= 10]
    f_big.append(statistics.mean(big))
print(f"| {seeds} | {statistics.mean(acc):.3f} | {statistics.mean(f_all):.3f} | "
      f"{statistics.mean(f_big):.3f} | {min(f_all):.3f}-{max(f_all):.3f} |")
PY
