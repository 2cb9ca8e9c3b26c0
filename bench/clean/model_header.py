#!/usr/bin/env python3
"""Prints the header of a mocap model file (safetensors) as JSON: format, description, data, training record.

    python3 bench/clean/model_header.py MODEL.safetensors > MODEL.json
"""
import json, struct, sys
b = open(sys.argv[1], 'rb').read()
n = struct.unpack('<Q', b[:8])[0]
h = json.loads(b[8:8 + n])
md = h.pop('__metadata__')
out = {
    "format": md['mocap.format'],
    "format_version": md['mocap.format_version'],
    "header": json.loads(md['mocap.header']),
    "tensors": {k: v['shape'] for k, v in sorted(h.items())},
}
print(json.dumps(out, indent=1))
