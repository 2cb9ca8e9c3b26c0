"""Parse throughput of the Python package bvhio on BVH files (reference for bench/core.sh).

Usage: python3 bench/bvhio_parse.py FILE...   (prints one JSON line)
"""
import json
import os
import sys
import time

import bvhio
from importlib.metadata import version

paths = sys.argv[1:]
total_bytes = sum(os.path.getsize(p) for p in paths)
start = time.thread_time()  # CPU time of this thread, as the Rust side measures
frames = 0
for p in paths:
    frames += bvhio.readAsBvh(p).FrameCount
seconds = time.thread_time() - start
print(json.dumps({
    "tool": f"bvhio {version('bvhio')}",
    "files": len(paths),
    "bytes": total_bytes,
    "frames": frames,
    "seconds": seconds,
    "mb_per_s": total_bytes / 1e6 / seconds,
}))
