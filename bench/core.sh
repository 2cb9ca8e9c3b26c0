#!/usr/bin/env bash
# Core benchmark: BVH parse throughput against the Python package bvhio, BVH
# write throughput and forward-kinematics throughput, side by side in one run
# on the Bandai BVH files. Writes bench/results/core.md.
#
# Usage: bench/core.sh [DATA_DIR]   (default ../shared/data/bandai/dataset-1)
set -euo pipefail
cd "$(dirname "$0")/.."
data=${1:-../shared/data/bandai/dataset-1}
venv=${BVHIO_VENV:-target/bench-venv}
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet bvhio
fi
mapfile -t files < <(find "$data" -name '*.bvh' | sort)
cargo build --release --quiet -p mocap-core --example bench_core --example bvh_peak_memory
ours=$(target/release/examples/bench_core "${files[@]}")
# Peak memory on a ~300 MB synthetic take (repeated frames of a Bandai file).
memory=$(target/release/examples/bvh_peak_memory --runs 1 2>&1 | grep '^run 1')
# bvhio is single-threaded pure Python; give it the same files, cache warm.
"$venv/bin/python" bench/bvhio_parse.py "${files[@]:0:5}" >/dev/null
theirs=$("$venv/bin/python" bench/bvhio_parse.py "${files[@]}")
python3 - "$ours" "$theirs" "$data" "$memory" <<'PY'
import json, platform, subprocess, sys, datetime
ours, theirs, data, memory = json.loads(sys.argv[1]), json.loads(sys.argv[2]), sys.argv[3], sys.argv[4]
cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), platform.processor())
ratio = ours["parse_mb_per_s"] / theirs["mb_per_s"]
fk = ours["fk_transforms_per_s"]
text = f"""# Core benchmark

Made by `bench/core.sh {data}` on {datetime.date.today()}, machine: {cpu}, {subprocess.getoutput('nproc')} cores.
Data: {ours['files']} BVH files, {ours['bytes']/1e6:.1f} MB, {ours['frames']} frames (Bandai Namco, 22 joints x 6 channels).
All numbers single-threaded CPU time of the working thread (fair on a shared machine), files in the page cache;
ours best of 3 (parse, write) or 5 (FK) passes, bvhio one pass after a warm-up on 5 files.

| measure | mocap | bvhio ({theirs['tool']}) | ratio |
| --- | ---: | ---: | ---: |
| BVH parse throughput (MB/s of text) | {ours['parse_mb_per_s']:.1f} | {theirs['mb_per_s']:.2f} | {ratio:.0f}x |
| BVH write throughput (MB/s of text, to memory) | {ours['write_mb_per_s']:.1f} | - | - |
| forward kinematics (joint transforms / s) | {fk/1e6:.1f} M | - | - |

Large files: `target/release/examples/bvh_peak_memory --runs 1` (a ~300 MB take made by repeating the frames
of the longest Bandai file, parsed once, wall time):

    {memory}

Targets of the core capability: parse >= 30x bvhio's MB/s: {'met' if ratio >= 30 else 'NOT met'}; FK >= 20 M joint transforms/s on one core: {'met' if fk >= 20e6 else 'NOT met'}.

Limits: bvhio is single-threaded pure Python, the only reader compared; write and FK throughput have no
reference here. Time in the page cache, not reading from disk.
"""
open("bench/results/core.md", "w").write(text)
print(text)
PY
