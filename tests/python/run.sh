#!/usr/bin/env bash
# The Python package's tests, from a machine with only Python 3.11 and cargo:
# a venv under ${CARGO_TARGET_DIR:-target}/py-venv with maturin, numpy,
# pytest and Ray (for mocap.batch); the `mocap` CLI (the tests compare with
# its output); the wheel, built by maturin and pip-installed into the venv;
# pytest on tests/python.
#
# The wheel is built in the dev profile at the test profile's opt-level (1,
# see Cargo.toml): the capability crates' artifacts that `cargo test
# --workspace` built are reused, and the shipped denoiser runs in seconds
# (at opt-level 0 it takes about a minute a take). Release wheels: `pip
# install ./crates/mocap-py` (docs/python.md) or bench/python/run.sh.
set -euo pipefail
cd "$(dirname "$0")/../.."

target="${CARGO_TARGET_DIR:-target}"
venv="$target/py-venv"
wheels="$target/py-wheels"

if [ ! -x "$venv/bin/python" ]; then
    mkdir -p "$target"
    python3 -m venv "$venv"
fi
venv="$(cd "$venv" && pwd)"
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check "maturin>=1.9.4,<2" numpy pytest
# Ray, for mocap.batch's tests (an optional dependency: not in the wheel's metadata).
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check "ray[default]"

echo "== the mocap CLI"
cargo build --quiet -p mocap-cli

echo "== the wheel"
rm -rf "$wheels"
CARGO_PROFILE_DEV_OPT_LEVEL=1 "$venv/bin/maturin" build --quiet -m crates/mocap-py/Cargo.toml \
    --profile dev --interpreter "$venv/bin/python" --out "$wheels"
wheel=$(ls "$wheels"/mocap-*.whl)
# numpy is the package's only run-time dependency.
"$venv/bin/python" - "$wheel" <<'PY'
import sys, zipfile
with zipfile.ZipFile(sys.argv[1]) as z:
    meta = next(n for n in z.namelist() if n.endswith(".dist-info/METADATA"))
    requires = [l for l in z.read(meta).decode().splitlines() if l.startswith("Requires-Dist:")]
names = [r.split(":", 1)[1].strip().split(">")[0].split("=")[0].split("<")[0].strip() for r in requires]
assert names == ["numpy"], f"run-time dependencies: {requires}"
print(f"{sys.argv[1]}: run-time dependencies {names}")
PY
"$venv/bin/python" -m pip uninstall --quiet --yes mocap 2>/dev/null || true
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check "$wheel"

echo "== pytest tests/python"
# From the tests' folder, so that `import mocap` is the installed wheel.
cli="$(cd "$target" && pwd)/debug/mocap"
cd tests/python
MOCAP_CLI="$cli" "$venv/bin/python" -m pytest -q -rs -p no:cacheprovider .
