#!/usr/bin/env bash
# The forest's F-measure over several fold assignments: 5-fold
# cross-validation by take with fold seeds 1..S (the forest seeds follow the
# fold number), forest only. One seed's F on a small data set moves by a
# clip or two; the mean over seeds is what a feature or parameter change is
# judged by.
#
#   bash bench/search/seeds.sh PATTERN FOLDER [SEEDS] [-- extra eval options]
#
# Prints one Markdown table row: seeds, mean accuracy, mean macro F over all
# classes, mean macro F over classes with >= 10 clips, and the lowest and
# highest F over all classes. EVAL=path runs another build of the eval
# example (e.g. one built from an older commit, to compare).
set -euo pipefail
cd "$(dirname "$0")/../.."
pattern=$1 folder=$2 seeds=${3:-20}
shift $(($# >= 3 ? 3 : 2))
[ "${1:-}" = "--" ] && shift
EVAL=${EVAL:-${CARGO_TARGET_DIR:-target}/release/examples/search_eval}
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT
for s in $(seq 1 "$seeds"); do
    "$EVAL" --labels-from-name "$pattern" --folds 5 --seed "$s" --no-baselines \
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
