#!/usr/bin/env bash
# mocap.batch against plain loops on the Bandai takes (bench/results/batch.md):
# clean with the shipped model (the CLI per take, mocap.clean in one Python
# process, mocap.batch.clean on a local Ray with 1 and 2 workers), the
# index (mocap search index against mocap.batch.index), and a projection
# for 1,000 hours. A release wheel with Ray in its own venv.
#   bench/batch/run.sh [TAKES]   (default all 1,165, about 40 min on 2 cores;
#                                 a number takes the first N; needs ../shared/data)
set -euo pipefail
cd "$(dirname "$0")/../.."
target="${CARGO_TARGET_DIR:-target}"
data="${MOCAP_SHARED_DATA:-../shared/data}/bandai"
takes="${1:-all}"
out=bench/results/batch.md

venv="$target/py-bench-venv"
[ -x "$venv/bin/python" ] || { mkdir -p "$target"; python3 -m venv "$venv"; }
venv="$(cd "$venv" && pwd)"
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check "maturin>=1.9.4,<2" numpy "ray[default]"
rm -rf "$target/py-wheels-release"
"$venv/bin/maturin" build --quiet --release -m crates/mocap-py/Cargo.toml \
    --interpreter "$venv/bin/python" --out "$target/py-wheels-release"
"$venv/bin/python" -m pip uninstall --quiet --yes mocap 2>/dev/null || true
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check "$target"/py-wheels-release/mocap-*.whl
cargo build --quiet --release -p mocap-cli

script="$(realpath bench/batch/bench.py)"
cli="$(realpath "$target/release/mocap")"
data="$(realpath "$data")"
# From /tmp, so that `import mocap` is the installed package.
table=$(cd /tmp && "$venv/bin/python" "$script" "$data" "$takes" "$cli")
{
    echo "# mocap.batch: takes/s on a local Ray"
    echo
    echo "Made by \`bench/batch/run.sh${1:+ $1}\` ($(date -u +%Y-%m-%d), $(git rev-parse --short HEAD), $(nproc) cores,"
    echo "load average $(cut -d' ' -f1 /proc/loadavg) at the end); the release wheel and the release CLI."
    echo
    echo "$table"
} > "$out"
cat "$out"
