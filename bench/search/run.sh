#!/usr/bin/env bash
# Regenerates bench/results/search.md: the search evaluation on the Bandai
# Namco clips (content and style labels, dataset-1 and dataset-2), the speed
# benchmark, and scikit-learn's random forest on the same feature matrix.
#
#   bash bench/search/run.sh            # about 10-15 minutes on 2 cores
#
# Needs ../shared/data (or MOCAP_SHARED_DATA) and, for the comparison,
# python3 with scikit-learn and numpy (pip install scikit-learn numpy).
set -euo pipefail
cd "$(dirname "$0")/../.."
DATA="${MOCAP_SHARED_DATA:-../shared/data}/bandai"
OUT=bench/results/search.md
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT

cargo build --release -p mocap-search --example search_eval --example bench
TARGET="${CARGO_TARGET_DIR:-target}/release/examples"

run_eval() { # name, label pattern, folder...
    local name=$1 pattern=$2
    shift 2
    local cmd="cargo run --release -p mocap-search --example search_eval -- --labels-from-name $pattern --folds 5 $*"
    echo "== $name" >&2
    {
        echo "## $name"
        echo
        echo "Command: \`$cmd\`"
        echo
        "$TARGET/search_eval" --labels-from-name "$pattern" --folds 5 "$@"
    } >"$TMP/$name.md"
}

run_eval "content-dataset-2" bandai-content "$DATA/dataset-2"
run_eval "content-dataset-1" bandai-content "$DATA/dataset-1"
run_eval "style-dataset-2" bandai-style "$DATA/dataset-2"
run_eval "style-dataset-1" bandai-style "$DATA/dataset-1"

# Across recording sessions: train on dataset-2, test on the dataset-1
# walks and runs (the two contents both datasets have).
mkdir -p "$TMP/d1-walk-run"
for f in "$DATA"/dataset-1/dataset-1_walk_*.bvh "$DATA"/dataset-1/dataset-1_run_*.bvh; do
    ln -s "$(realpath "$f")" "$TMP/d1-walk-run/"
done
mkdir -p "$TMP/d2-walk-run"
for f in "$DATA"/dataset-2/dataset-2_walk_*.bvh "$DATA"/dataset-2/dataset-2_run_*.bvh; do
    ln -s "$(realpath "$f")" "$TMP/d2-walk-run/"
done
{
    echo "## content, trained on dataset-2 walk/run, tested on dataset-1 walk/run"
    echo
    echo "Command: \`cargo run --release -p mocap-search --example search_eval -- --labels-from-name bandai-content --no-unseen --no-takes D2_WALK_RUN --test D1_WALK_RUN\` (folders of links to the walk_ and run_ files)"
    echo
    "$TARGET/search_eval" --labels-from-name bandai-content --no-unseen --no-takes \
        --name "dataset-2 walk/run -> dataset-1 walk/run" "$TMP/d2-walk-run" --test "$TMP/d1-walk-run"
} >"$TMP/cross.md"

# One fold assignment of a small data set moves F by a clip or two: the
# forest's mean over fold seeds (bench/search/seeds.sh).
echo "== fold seeds" >&2
{
    echo "## Spread over fold seeds (forest only)"
    echo
    echo "Command: \`bash bench/search/seeds.sh PATTERN FOLDER SEEDS\` (5-fold by take with fold seeds 1..SEEDS; the tables above use seed 1). \"F, >= 10 clips\" is the macro F over the classes with at least 10 clips; \"F, all\" over all classes evaluated."
    echo
    echo "| data | labels | seeds | accuracy | F, all | F, >= 10 clips | F, all: lowest-highest |"
    echo "| --- | --- | ---: | ---: | ---: | ---: | --- |"
    for spec in "dataset-1 bandai-content 20" "dataset-1 bandai-style 20" "dataset-2 bandai-content 5" "dataset-2 bandai-style 5"; do
        set -- $spec
        echo "| $1 | $2 $(EVAL="$TARGET/search_eval" bash bench/search/seeds.sh "$2" "$DATA/$1" "$3")"
    done
} >"$TMP/seeds.md"

echo "== speed" >&2
"$TARGET/bench" --labels-from-name bandai-content --features-csv "$TMP/features.csv" "$DATA/dataset-2" >"$TMP/bench.md"
if python3 -c "import sklearn" 2>/dev/null; then
    python3 bench/search/sklearn_compare.py "$TMP/features.csv" --jobs 2 >>"$TMP/bench.md"
    python3 bench/search/sklearn_compare.py "$TMP/features.csv" --jobs 1 >>"$TMP/bench.md"
else
    echo "| scikit-learn | not installed | | |" >>"$TMP/bench.md"
fi

{
    cat bench/search/header.md
    echo
    echo "## Speed"
    echo
    echo "Command: \`cargo run --release -p mocap-search --example bench -- --labels-from-name bandai-content --features-csv FILE $DATA/dataset-2\`, then \`python3 bench/search/sklearn_compare.py FILE --jobs 2\` and \`--jobs 1\` (scikit-learn rows)."
    echo
    cat "$TMP/bench.md"
    echo
    for name in content-dataset-2 content-dataset-1 style-dataset-2 style-dataset-1; do
        cat "$TMP/$name.md"
        echo
    done
    cat "$TMP/cross.md"
    echo
    cat "$TMP/seeds.md"
} >"$OUT.tmp"
mv "$OUT.tmp" "$OUT"
echo "wrote $OUT" >&2
