"""Type stubs of the Rust extension of the ``mocap`` package (import ``mocap``)."""

import os
from typing import Literal, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

PathLike = Union[str, os.PathLike[str]]
FloatArray = npt.NDArray[np.float32]
ArrayLike = npt.ArrayLike

class MocapError(ValueError):
    """An input mocap cannot use: a malformed file (the message names its
    path, line and column), a rig without a body part a method needs, arrays
    of the wrong shape. Files that cannot be opened raise OSError
    (FileNotFoundError when missing)."""

class Skeleton:
    """A skeleton: joints (parents before children), rest offsets and each
    joint's channels in file order. ``len(skeleton)`` is its number of joints."""

    @property
    def joint_names(self) -> list[str]:
        """Joint names, in skeleton order."""
    @property
    def parents(self) -> list[int]:
        """Parent index of every joint, -1 for a root."""
    @property
    def offsets(self) -> FloatArray:
        """Rest offsets from each joint's parent, float32, joints x 3."""
    @property
    def channel_names(self) -> list[str]:
        """``JOINT.CHANNEL`` for every channel in file order (``Hips.Zrotation``)."""
    def __len__(self) -> int: ...

class Motion:
    """A motion: a skeleton, a frame time and the channel values of every
    frame (rotations in degrees, positions in the file's units). Immutable:
    every operation returns a new motion. ``len(motion)`` is its number of
    frames; ``motion[a:b]`` its frames a to b (contiguous slices only)."""

    @staticmethod
    def from_arrays(
        skeleton: Union["Motion", Skeleton],
        rotations: ArrayLike,
        root_positions: ArrayLike,
        frame_time: float,
        translations: Optional[ArrayLike] = None,
    ) -> "Motion":
        """A motion of ``skeleton`` (a Skeleton, or a Motion whose skeleton is
        taken) from local joint rotations, quaternions (w, x, y, z) frames x
        joints x 4 as ``rotations("quat", "local")`` gives them, and the root's
        positions frames x 3 (``positions()[:, 0]``). Rotations are written as
        Euler angles in each joint's channel order, each frame's nearest the
        previous frame's. Other joints with position channels take
        ``translations`` (frames x joints x 3, as ``translations()`` gives
        them) when given, else their rest offsets. ``frame_time`` in seconds.
        Raises MocapError for arrays of the wrong shape."""
    @property
    def skeleton(self) -> Skeleton:
        """The skeleton (joints, offsets, channels)."""
    @property
    def joint_names(self) -> list[str]:
        """Joint names, in skeleton order."""
    @property
    def parents(self) -> list[int]:
        """Parent index of every joint, -1 for a root."""
    @property
    def offsets(self) -> FloatArray:
        """Rest offsets from each joint's parent, float32, joints x 3."""
    @property
    def frame_time(self) -> float:
        """Seconds between frames, as written in the file."""
    @property
    def fps(self) -> float:
        """Frames per second."""
    @property
    def duration(self) -> float:
        """Length of the take in seconds."""
    @property
    def channels(self) -> FloatArray:
        """The channel values, float32, frames x channels (a copy): rotations in
        degrees, positions in the file's units, columns as ``channel_names``."""
    @property
    def channel_names(self) -> list[str]:
        """``JOINT.CHANNEL`` for every column of ``channels``."""
    def positions(self) -> FloatArray:
        """Global joint positions by forward kinematics, float32,
        frames x joints x 3, in the file's units."""
    def rotations(
        self,
        kind: Literal["quat", "matrix", "expmap", "6d"] = "quat",
        space: Literal["local", "global"] = "local",
    ) -> FloatArray:
        """Joint rotations of every frame, float32: ``kind`` "quat" (frames x
        joints x 4, w, x, y, z), "matrix" (frames x joints x 3 x 3, row by row:
        a matrix times a column vector rotates it), "expmap" (x 3, axis times
        angle in radians) or "6d" (x 6, the matrix's first two columns);
        ``space`` "local" (relative to the parent) or "global" (forward
        kinematics). Raises MocapError for another kind or space."""
    def translations(self) -> FloatArray:
        """Local joint translations (position channels where a joint has them,
        else its rest offset), float32, frames x joints x 3."""
    def write(self, path: PathLike) -> None:
        """Writes the motion to ``path``, atomically: BVH (``.bvh``) or glTF
        (``.glb``, ``.gltf``: a skinned body in metres, Y up)."""
    def __len__(self) -> int: ...
    def __getitem__(self, frames: slice) -> "Motion":
        """The frames ``a:b`` as a new motion (the step must be 1)."""

def read(path: PathLike, amc: Optional[PathLike] = None) -> Motion:
    """Reads a motion file: BVH, an ASF skeleton with its AMC motion
    (``read("x.asf", "x.amc")``, or the AMC alone with its ASF beside it), or
    a sensor recording (``.jsonl``, NTU ``.skeleton``), or glTF (``.glb``,
    ``.gltf``: the first skin and its first animation). Raises
    FileNotFoundError for a missing file and MocapError for a malformed one,
    naming its path, line and column."""

def clean(
    motion: Motion, model: Optional[PathLike] = None, filter: Optional[str] = None
) -> Motion:
    """Denoises a motion as ``mocap clean apply`` does: with the model shipped
    with mocap (default), a model file (``model``), or a classical filter
    (``filter``, the CLI's SPEC: "butterworth:ORDER:HZ", "butterworth-gcv:ORDER",
    "savitzky-golay:WINDOW:POLYORDER", "median:WINDOW",
    "one-euro:MIN_HZ:BETA:D_HZ"). Only rotations change. Runs on the CPU."""

def feet(motion: Motion, floor: Optional[float] = None) -> Motion:
    """Holds planted feet still and above the floor, as ``mocap feet`` does.
    ``floor``: the floor's height along the up axis (default: estimated)."""

def retarget(motion: Motion, onto: Union[Motion, Skeleton]) -> Motion:
    """The motion played by another rig (``onto``: a Motion or Skeleton of it),
    body parts found by joint name, as ``mocap convert --retarget``."""

def resample(motion: Motion, fps: float) -> Motion:
    """The motion at ``fps`` frames per second over the same time span."""

def mirror(motion: Motion) -> Motion:
    """The mirror image: left and right swapped."""

def style_apply(
    source: Union[Motion, PathLike],
    style: Union[Motion, PathLike],
    strength: float = 1.0,
    model: Optional[PathLike] = None,
) -> Motion: ...
def fuse_run(
    recordings: Sequence[PathLike],
    calib: PathLike,
    body: Optional[PathLike] = None,
    method: str = "best",
    fps: float = 30.0,
) -> Motion: ...

class Match:
    """One ranked library clip."""

    @property
    def rank(self) -> int:
        """1 for the nearest clip."""
    @property
    def path(self) -> str:
        """The clip's file."""
    @property
    def label(self) -> str:
        """The clip's class label."""
    @property
    def distance(self) -> float:
        """Its distance to the query (smaller is nearer)."""

class QueryResult:
    """The answer to a query: the predicted label, every label's probability
    and the ranked library clips. ``str(result)`` is the CLI's text."""

    @property
    def label(self) -> str:
        """The predicted class label."""
    @property
    def probability(self) -> float:
        """The predicted label's probability."""
    @property
    def probabilities(self) -> list[tuple[str, float]]:
        """Every label with a non-zero probability, most likely first."""
    @property
    def matches(self) -> list[Match]:
        """The nearest library clips, best first."""

class Index:
    """A motion library for retrieval by example (``mocap search index``
    writes one). ``len(index)`` is its number of clips."""

    @staticmethod
    def load(path: PathLike) -> "Index":
        """Reads an index file written by ``mocap search index``."""
    @staticmethod
    def bundled() -> "Index":
        """The index shipped with mocap (the Bandai dataset's contents); its
        clip paths are relative to the repository's models/ folder."""
    @property
    def classes(self) -> list[str]:
        """The class labels the forest knows."""
    def query(
        self,
        clip: Union[Motion, PathLike],
        top: int = 10,
        rank: Literal["histogram", "proximity", "features"] = "histogram",
    ) -> QueryResult:
        """Classifies a clip (a Motion or a path) and ranks the library's clips
        by similarity (the best ``top``), as ``mocap search query``."""
    def __len__(self) -> int: ...

# The steps of mocap.batch.index (use that, not these).
def search_clips(
    inputs: Sequence[PathLike],
    labels: Optional[PathLike] = None,
    labels_from_name: Optional[str] = None,
) -> tuple[list[tuple[str, str, Optional[str]]], str]:
    """The clips ``mocap search index`` would index, in its order, with their
    labels and performers, and the label rule's name."""
def search_features(path: PathLike) -> tuple[FloatArray, float]:
    """One clip's per-frame pose features (frames x values) and frame rate."""
def search_build_index(
    clips: Sequence[tuple[str, str, Optional[str]]],
    features: Sequence[tuple[FloatArray, float]],
    rule_name: str,
    output: PathLike,
    trees: int = 100,
    candidates: int = 64,
    min_entropy: float = 0.0,
    frames: int = 10,
    seed: int = 1,
    bootstrap: bool = True,
) -> tuple[int, int]:
    """Trains the forest on the clips and writes the index, as ``mocap search
    index``; returns the numbers of clips and classes."""
