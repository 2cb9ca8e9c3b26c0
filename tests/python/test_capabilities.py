"""The capabilities from Python: each against what its CLI command does or
what it must keep, on the bundled takes and the shared data."""

import json
import subprocess
import threading
import time

import numpy as np
import pytest

import mocap
from conftest import INDEX, PROUD, SAMPLE


def rotation_columns(m):
    return [i for i, n in enumerate(m.channel_names) if n.endswith("rotation")]


def test_clean_with_the_shipped_model(walk):
    cleaned = mocap.clean(walk)
    assert cleaned.joint_names == walk.joint_names and len(cleaned) == len(walk)
    change = np.abs(cleaned.channels - walk.channels)
    assert 0 < change.max() < 10  # degrees: a clean take is changed a little
    positions = [i for i, n in enumerate(walk.channel_names) if n.endswith("position")]
    np.testing.assert_array_equal(cleaned.channels[:, positions], walk.channels[:, positions])


def test_clean_as_the_cli(walk, cli, tmp_path):
    out = tmp_path / "clean.bvh"
    subprocess.run([cli, "-q", "clean", "apply", str(SAMPLE), "--filter", "butterworth:2:6", "-o", str(out)], check=True)
    ours = mocap.clean(walk, filter="butterworth:2:6")
    np.testing.assert_allclose(ours.channels, mocap.read(out).channels, rtol=1e-5, atol=1e-3)
    smoother = np.abs(np.diff(ours.channels[:, rotation_columns(walk)], 2, axis=0)).mean()
    rough = np.abs(np.diff(walk.channels[:, rotation_columns(walk)], 2, axis=0)).mean()
    assert smoother < rough


def test_clean_errors(walk):
    with pytest.raises(mocap.MocapError, match="median:0|window|filter"):
        mocap.clean(walk, filter="median:0")
    with pytest.raises(mocap.MocapError):
        mocap.clean(walk, filter="no-such-filter:1")
    with pytest.raises(mocap.MocapError, match="not both"):
        mocap.clean(walk, model="x.safetensors", filter="median:5")
    with pytest.raises(FileNotFoundError, match="x.safetensors"):
        mocap.clean(walk, model="x.safetensors")


def test_clean_releases_the_gil(walk):
    done = threading.Event()
    ticks = 0

    def work():
        mocap.clean(walk)
        done.set()

    thread = threading.Thread(target=work)
    thread.start()
    while not done.is_set():
        ticks += 1
        time.sleep(0)
    thread.join()
    assert ticks > 100, f"the main thread ran {ticks} times while clean() worked"


def test_feet_as_the_cli(walk, cli, tmp_path):
    out = tmp_path / "feet.bvh"
    subprocess.run([cli, "-q", "feet", str(SAMPLE), "-o", str(out)], check=True)
    planted = mocap.feet(walk)
    assert planted.joint_names == walk.joint_names and len(planted) == len(walk)
    np.testing.assert_allclose(planted.channels, mocap.read(out).channels, rtol=1e-5, atol=1e-3)
    assert mocap.feet(walk, floor=0.0).channels.shape == walk.channels.shape


def test_search_with_the_bundled_index(walk):
    index = mocap.search.Index.bundled()
    assert len(index) > 100 and "walk" in index.classes
    result = index.query(walk, top=5)
    assert result.label == "walk"
    assert 0 < result.probability <= 1
    assert result.probabilities[0] == (result.label, pytest.approx(result.probability))
    assert sum(p for _, p in result.probabilities) == pytest.approx(1, abs=1e-3)
    assert [m.rank for m in result.matches] == [1, 2, 3, 4, 5]
    distances = [m.distance for m in result.matches]
    assert distances == sorted(distances)
    assert "walk" in str(result)
    with pytest.raises(mocap.MocapError, match="unknown ranking"):
        index.query(walk, rank="cosine")


def test_search_as_the_cli(walk, cli):
    out = subprocess.run(
        [cli, "search", "query", str(SAMPLE), "--index", str(INDEX), "--top", "10", "--json"],
        check=True, capture_output=True,
    )
    theirs = json.loads(out.stdout)
    index = mocap.search.Index.load(INDEX)
    for clip in (SAMPLE, walk):  # a path, as the CLI, and the motion read from it
        ours = index.query(clip, top=10)
        assert ours.label == theirs["predicted"]
        assert ours.probability == pytest.approx(theirs["probability"])
        assert [c for c, _ in ours.probabilities] == [p["class"] for p in theirs["probabilities"]]
        assert [m.path for m in ours.matches] == [m["path"] for m in theirs["matches"]]
        assert [m.distance for m in ours.matches] == pytest.approx([m["distance"] for m in theirs["matches"]])


def test_search_index_errors(tmp_path):
    with pytest.raises(FileNotFoundError):
        mocap.search.Index.load(tmp_path / "none.idx")
    bad = tmp_path / "bad.idx"
    bad.write_bytes(b"not an index at all")
    with pytest.raises(mocap.MocapError, match="bad.idx"):
        mocap.search.Index.load(bad)


def test_search_shared_clips_exist(shared):
    index = mocap.search.Index.load(INDEX)
    clip = sorted((shared / "bandai" / "dataset-1").glob("dataset-1_run_*.bvh"))[0]
    result = index.query(clip, top=3)
    assert result.label == "run"
    from pathlib import Path
    assert all(Path(m.path).is_file() for m in result.matches)


def test_style_apply(walk, cli, tmp_path):
    restyled = mocap.style.apply(walk, PROUD, strength=0.7)
    assert restyled.joint_names == walk.joint_names
    assert restyled.fps == pytest.approx(walk.fps, rel=1e-3)
    assert len(restyled) > 100
    assert np.isfinite(restyled.channels).all()
    # The same as the command on the same files.
    out = tmp_path / "styled.bvh"
    subprocess.run(
        [cli, "-q", "style", "apply", str(SAMPLE), "--style", str(PROUD), "--strength", "0.7", "-o", str(out)],
        check=True,
    )
    from_paths = mocap.style.apply(SAMPLE, PROUD, strength=0.7)
    np.testing.assert_allclose(from_paths.channels, mocap.read(out).channels, rtol=1e-5, atol=1e-2)
    with pytest.raises(mocap.MocapError, match="too short"):
        mocap.style.apply(walk, mocap.read(PROUD)[:10])


def test_fuse_run(cli, tmp_path):
    subprocess.run([cli, "-q", "fuse", "simulate", str(SAMPLE), "-o", str(tmp_path)], check=True)
    recordings = sorted(tmp_path.glob("sensor-*.jsonl"))
    assert len(recordings) == 3
    fused = mocap.fuse.run(recordings, tmp_path / "truth.calib.toml")
    assert fused.joint_names[0] == "SpineBase" and len(fused.joint_names) == 25
    assert len(fused) > 150 and fused.fps == pytest.approx(30)
    out = tmp_path / "fused.bvh"
    subprocess.run(
        [cli, "-q", "fuse", "run", *map(str, recordings), "--calib", str(tmp_path / "truth.calib.toml"), "-o", str(out)],
        check=True, capture_output=True,
    )
    np.testing.assert_allclose(fused.channels, mocap.read(out).channels, rtol=1e-5, atol=1e-3)
    # One sensor's recording reads as a motion too (the registered readers).
    one = mocap.read(recordings[0])
    assert one.joint_names == fused.joint_names
    with pytest.raises(FileNotFoundError, match="nowhere.toml"):
        mocap.fuse.run(recordings, tmp_path / "nowhere.toml")


def test_resample(walk):
    same = mocap.resample(walk, walk.fps)
    np.testing.assert_allclose(same.channels, walk.channels, atol=1e-4)
    double = mocap.resample(walk, 60)
    assert double.fps == pytest.approx(60) and len(double) in (388, 389)
    np.testing.assert_allclose(double.positions()[::2][:150], walk.positions()[:150], atol=0.05)
    with pytest.raises(mocap.MocapError, match="positive"):
        mocap.resample(walk, -1)


def test_mirror(walk):
    mirrored = mocap.mirror(walk)
    assert mirrored.joint_names == walk.joint_names
    assert not np.allclose(mirrored.positions(), walk.positions(), atol=1)
    np.testing.assert_allclose(mocap.mirror(mirrored).positions(), walk.positions(), atol=1e-2)


def test_retarget(walk, shared):
    cmu = mocap.read(shared / "other-rigs/cmu-asf/16_01.bvh")
    moved = mocap.retarget(walk, onto=cmu)
    assert moved.joint_names == cmu.joint_names and len(moved) == len(walk)
    assert moved.frame_time == pytest.approx(walk.frame_time)
    same = mocap.retarget(walk, onto=cmu.skeleton)
    np.testing.assert_array_equal(same.channels, moved.channels)


def test_retarget_errors(walk):
    with pytest.raises(TypeError, match="Motion or a mocap.Skeleton"):
        mocap.retarget(walk, onto="rig.bvh")
    with pytest.raises(TypeError):
        mocap.clean("take.bvh")
