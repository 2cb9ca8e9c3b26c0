"""Fixtures of the Python package's tests: the bundled samples, the shared
data (``$MOCAP_SHARED_DATA`` or ``../shared/data`` beside the repository, as
crates/mocap-testdata finds it) and the ``mocap`` command (``$MOCAP_CLI``)."""

import os
import shutil
from pathlib import Path

import pytest

import mocap

REPO = Path(__file__).resolve().parents[2]
SAMPLE = REPO / "samples" / "dataset-1_walk_normal_001.bvh"
PROUD = REPO / "samples" / "dataset-1_walk_proud_001.bvh"
INDEX = REPO / "models" / "search-bandai-content.idx"


def shared_data_dir() -> Path:
    override = os.environ.get("MOCAP_SHARED_DATA")
    return Path(override) if override else REPO.parent / "shared" / "data"


@pytest.fixture(scope="package")
def walk() -> "mocap.Motion":
    return mocap.read(SAMPLE)


@pytest.fixture
def shared() -> Path:
    """The shared data folder; the test is skipped, with the reason, when it is absent."""
    folder = shared_data_dir()
    if not folder.is_dir():
        pytest.skip(f"shared data not found at {folder} (set MOCAP_SHARED_DATA)")
    return folder


@pytest.fixture(scope="package")
def cli() -> str:
    """The `mocap` binary: $MOCAP_CLI (tests/python/run.sh builds it), else on PATH."""
    path = os.environ.get("MOCAP_CLI") or shutil.which("mocap")
    if not path:
        pytest.skip("the mocap CLI was not found (set MOCAP_CLI; tests/python/run.sh does)")
    return path
