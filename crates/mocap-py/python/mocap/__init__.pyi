"""mocap: motion capture in Python (see ``_mocap.pyi`` for the classes)."""

from . import fuse as fuse
from . import search as search
from . import style as style
from ._mocap import MocapError as MocapError
from ._mocap import Motion as Motion
from ._mocap import Skeleton as Skeleton
from ._mocap import clean as clean
from ._mocap import feet as feet
from ._mocap import mirror as mirror
from ._mocap import read as read
from ._mocap import resample as resample
from ._mocap import retarget as retarget

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
