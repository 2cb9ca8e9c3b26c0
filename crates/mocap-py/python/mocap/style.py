"""Zero-shot style transfer from one example clip (``mocap style apply``)."""

from __future__ import annotations

import os
from typing import Optional, Union

from . import _mocap
from ._mocap import Motion

__all__ = ["apply"]


def apply(
    source: Union[Motion, str, os.PathLike],
    style: Union[Motion, str, os.PathLike],
    strength: float = 1.0,
    model: Union[str, os.PathLike, None] = None,
) -> Motion:
    """Restyles ``source`` in the style of the example clip ``style``, as
    ``mocap style apply SOURCE --style STYLE`` does.

    source, style: Motions or paths of motion files; a style clip of another
        rig than the model's is retargeted.
    strength: 1 gives the full style, 0 the source; in between the pose and
        the timing are interpolated (the CLI's ``--strength``, default 1).
    model: a model file from ``mocap style train`` (default: the shipped one).

    Returns the restyled motion, on the source's skeleton; its length follows
    the style's timing. Raises MocapError for a rig the model cannot use or a
    style clip shorter than one patch.
    """
    return _mocap.style_apply(source, style, strength, model)
