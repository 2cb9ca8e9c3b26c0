"""mocap: motion capture in Python.

Read BVH, ASF/AMC and sensor recordings into numpy arrays, compute forward
kinematics, and clean, plant feet, search, restyle and fuse takes with the
mocap toolkit's Rust libraries.

>>> import mocap
>>> m = mocap.read("samples/dataset-1_walk_normal_001.bvh")
>>> m.positions().shape            # frames x joints x 3
(196, 22, 3)
"""

from ._mocap import (
    MocapError,
    Motion,
    Skeleton,
    clean,
    feet,
    mirror,
    read,
    resample,
    retarget,
)
from . import fuse, search, style

__all__ = [
    "MocapError",
    "Motion",
    "Skeleton",
    "clean",
    "feet",
    "fuse",
    "mirror",
    "read",
    "resample",
    "retarget",
    "search",
    "style",
]
