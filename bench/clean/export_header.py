#!/usr/bin/env python3
"""Writes the safetensors header of a mocap model (description, data, training) as readable JSON.

usage: export_header.py MODEL.safetensors OUT.json
"""
import json
import struct
import sys

with open(sys.argv[1], "rb") as f:
    (n,) = struct.unpack("<Q", f.read(8))
    header = json.loads(f.read(n))
meta = header.get("__metadata__", {})
out = {
    "format": meta.get("mocap.format"),
    "format_version": meta.get("mocap.format_version"),
    "header": json.loads(meta["mocap.header"]),
    "tensors": {k: v["shape"] for k, v in header.items() if k != "__metadata__"},
}
with open(sys.argv[2], "w") as f:
    json.dump(out, f, indent=1)
