#!/usr/bin/env bash
# Reproduces the tables of bench/results/search.md into bench/search/out/: the search evaluation on the Bandai clips
# (content and style labels, dataset-1 and dataset-2, the walk/run transfer), the spread over fold seeds and speed.
#
#   bash bench/search/run.sh            # about 10-15 minutes on 2 cores
#
# Needs ../shared/data (or MOCAP_SHARED_DATA) and, for the speed comparison, python3 with scikit-learn and numpy.
# MOCAP=path/to/mocap runs a built binary instead of `cargo run --release -p mocap-cli`.
set -euo pipefail
cd "$(dirname "$0")/../.."
DATA="${MOCAP_SHARED_DATA:-../shared/data}/bandai"
OUT=bench/search/out
MOCAP=${MOCAP:-cargo run --release -q -p mocap-cli --}
mkdir -p "$OUT"
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT

run_eval() { # name, label pattern, folder...
    local name=$1 pattern=$2
    shift 2
    echo "== $name" >&2
    $MOCAP -q search eval --labels-from-name "$pattern" --folds 5 --markdown "$OUT/$name.md" "$@" >/dev/null
}

run_eval content-dataset-2 bandai-content "$DATA/dataset-2"
run_eval content-dataset-1 bandai-content "$DATA/dataset-1"
run_eval style-dataset-2 bandai-style "$DATA/dataset-2"
run_eval style-dataset-1 bandai-style "$DATA/dataset-1"

# Across recordings: train on the dataset-2 walks and runs, test on the dataset-1 ones.
mkdir -p "$TMP/d1-walk-run" "$TMP/d2-walk-run"
for f in "$DATA"/dataset-1/dataset-1_walk_*.bvh "$DATA"/dataset-1/dataset-1_run_*.bvh; do
    ln -s "$(realpath "$f")" "$TMP/d1-walk-run/"
done
for f in "$DATA"/dataset-2/dataset-2_walk_*.bvh "$DATA"/dataset-2/dataset-2_run_*.bvh; do
    ln -s "$(realpath "$f")" "$TMP/d2-walk-run/"
done
echo "== walk-run-transfer" >&2
$MOCAP -q search eval --labels-from-name bandai-content --no-unseen --no-takes \
    --name "dataset-2 walk/run -> dataset-1 walk/run" --markdown "$OUT/walk-run-transfer.md" \
    "$TMP/d2-walk-run" --test "$TMP/d1-walk-run" >/dev/null

echo "== fold seeds" >&2
{
    echo "| data | labels | seeds | accuracy | F, all | F, >= 10 clips | F, all: lowest-highest |"
    echo "| --- | --- | ---: | ---: | ---: | ---: | --- |"
    for spec in "dataset-1 bandai-content 20" "dataset-1 bandai-style 20" "dataset-2 bandai-content 5" "dataset-2 bandai-style 5"; do
        set -- $spec
        echo "| $1 | $2 $(MOCAP="$MOCAP" bash bench/search/seeds.sh "$2" "$DATA/$1" "$3")"
    done
} >"$OUT/seeds.md"

echo "== speed" >&2
cargo build --release -q -p mocap-search --example bench
"${CARGO_TARGET_DIR:-target}/release/examples/bench" --labels-from-name bandai-content \
    --features-csv "$TMP/features.csv" "$DATA/dataset-2" >"$OUT/speed.md"
if python3 -c "import sklearn" 2>/dev/null; then
    python3 bench/search/sklearn_compare.py "$TMP/features.csv" --jobs 2 >>"$OUT/speed.md"
    python3 bench/search/sklearn_compare.py "$TMP/features.csv" --jobs 1 >>"$OUT/speed.md"
else
    echo "| scikit-learn | not installed | | |" >>"$OUT/speed.md"
fi

echo "== unseen pairs" >&2
cargo run --release -q -p mocap-studies --example search_unseen_pairs -- "$DATA/dataset-2" 5 >"$OUT/unseen-pairs.md"
echo "wrote $OUT" >&2
