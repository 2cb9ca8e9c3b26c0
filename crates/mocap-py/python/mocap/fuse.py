"""Several calibrated depth sensors fused by confidence (``mocap fuse``)."""

from __future__ import annotations

import os
from typing import Optional, Sequence, Union

from . import _mocap
from ._mocap import Motion

__all__ = ["run"]

PathLike = Union[str, os.PathLike]


def run(
    recordings: Sequence[PathLike],
    calib: PathLike,
    body: Optional[PathLike] = None,
    method: str = "best",
    fps: float = 30.0,
) -> Motion:
    """Fuses sensor recordings into one motion, as ``mocap fuse run
    RECORDINGS... --calib CALIB -o out.bvh`` does.

    recordings: the sensors' recordings (``.jsonl``, NTU ``.skeleton``).
    calib: the calibration file (every sensor's pose).
    body: the person's body file (default: measured from the recordings).
    method: the fusion method (the CLI's ``--method``, default "best").
    fps: fused frames per second.

    Returns the fused take as a motion on a fitted skeleton, in centimetres,
    standing upright on the floor found under the feet.
    """
    return _mocap.fuse_run([os.fspath(r) for r in recordings], calib, body, method, fps)
