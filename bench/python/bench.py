"""The Python package against Rust and bvhio (run by bench/python/run.sh).

Usage: python bench.py LONG_TAKE.bvh RUST_FK_JSON COMMAND BVH_FILE...
Writes bench/results/python.md.
"""
import json
import os
import platform
import sys
import time
from importlib.metadata import version
from pathlib import Path

import bvhio
import numpy as np

import mocap

RUNS = 5
long_take, rust_json, command, *files = sys.argv[1:]
rust = json.loads(rust_json)

# (a) Forward kinematics of the long take: m.positions(), best of RUNS.
m = mocap.read(long_take)
best = float("inf")
for _ in range(RUNS):
    start = time.perf_counter()
    positions = m.positions()
    best = min(best, time.perf_counter() - start)
assert positions.shape == (rust["frames"], rust["joints"], 3)
assert abs(float(positions[..., 0].astype(np.float64).sum()) - rust["checksum"]) <= 1e-6 * max(1.0, abs(rust["checksum"])) + 1.0
fk_ratio = best / rust["seconds"]

# (b) Reading BVH files: mocap.read against bvhio.readAsBvh, one pass each
# after a warm-up pass on a few files (cache warm), wall-clock time.
total_bytes = sum(os.path.getsize(f) for f in files)
for f in files[:3]:
    mocap.read(f)
    bvhio.readAsBvh(f)


def read_all(read):
    start = time.perf_counter()
    frames = 0
    for f in files:
        frames += read(f)
    return time.perf_counter() - start, frames


ours_s, ours_frames = min(
    (read_all(lambda f: len(mocap.read(f))) for _ in range(3)), key=lambda r: r[0]
)
theirs_s, theirs_frames = read_all(lambda f: bvhio.readAsBvh(f).FrameCount)
assert ours_frames == theirs_frames, (ours_frames, theirs_frames)
read_ratio = theirs_s / ours_s

minutes = rust["frames"] * m.frame_time / 60
text = f"""# The Python package: speed

Made by `{command}` ({platform.processor() or platform.machine()}, Python {platform.python_version()},
numpy {np.__version__}, bvhio {version('bvhio')}; the release wheel; one run).

## (a) Forward kinematics of a long take

`m.positions()` on `{Path(long_take).name}`: {rust['frames']} frames ({minutes:.1f} minutes at
{m.fps:.0f} fps) of {rust['joints']} joints, `dataset-1`'s longest take looped by `mocap convert` (Bandai's takes differ in their
skeletons, so they cannot be joined).
Best of {RUNS} runs each.

| | seconds | frames/s |
| --- | ---: | ---: |
| Python `m.positions()` (frames × joints × 3 float32 array) | {best:.4f} | {rust['frames'] / best:,.0f} |
| Rust `mocap_core::forward_kinematics` (`crates/mocap-py/examples/fk_timing.rs`) | {rust['seconds']:.4f} | {rust['frames'] / rust['seconds']:,.0f} |
| ratio Python / Rust | {fk_ratio:.2f} | |

Target: within 2x of the Rust FK: **{'met' if fk_ratio <= 2 else 'NOT met'}**. What each side does: the
Rust figure is the core's FK of every frame into `GlobalPoses` (global positions and
rotations), the file read beforehand; the Python figure is the same FK run a piece of
1024 frames at a time (as every whole-take pass in the core) with the positions copied
into one numpy array and the GIL released, the motion read beforehand.

## (b) Reading BVH files

{len(files)} Bandai files of `dataset-1` ({total_bytes / 1e6:.1f} MB, {ours_frames} frames), one after
another in one thread, wall-clock time; mocap best of 3 passes, bvhio one pass, both after a
warm-up on 3 files.

| reader | seconds | MB/s |
| --- | ---: | ---: |
| `mocap.read` | {ours_s:.3f} | {total_bytes / 1e6 / ours_s:.1f} |
| `bvhio.readAsBvh` {version('bvhio')} | {theirs_s:.3f} | {total_bytes / 1e6 / theirs_s:.2f} |
| ratio | {read_ratio:.0f}x | |

Target: at least 20x faster than bvhio: **{'met' if read_ratio >= 20 else 'NOT met'}**. `mocap.read` includes
building the Python `Motion` object (the channel values stay in Rust until asked for);
bvhio builds its Python object tree of joints and keyframes.
"""
Path("bench/results/python.md").write_text(text)
print(text)
