"""mocap.Motion and mocap.read: arrays, forward kinematics, round trips,
slicing and errors, on the bundled Bandai walk and the shared data."""

import re
import subprocess
import threading
import time

import numpy as np
import pytest

import mocap
from conftest import PROUD, SAMPLE


def test_read_describes_the_take(walk):
    assert len(walk) == 195
    assert walk.frame_time == pytest.approx(0.0333333)
    assert walk.fps == pytest.approx(30.0, rel=1e-5)
    assert walk.duration == pytest.approx(195 * 0.0333333)
    assert len(walk.joint_names) == 22
    assert walk.joint_names[:3] == ["joint_Root", "Hips", "Spine"]
    assert walk.parents[:3] == [-1, 0, 1]
    assert all(p < j for j, p in enumerate(walk.parents))
    assert walk.offsets.shape == (22, 3) and walk.offsets.dtype == np.float32
    np.testing.assert_allclose(walk.offsets[1], [0, 93.9241, -3], rtol=1e-6)
    assert re.fullmatch(r"<mocap\.Motion: 22 joints, 195 frames at 30\.0+ fps \(6\.50 s\)>", repr(walk))
    skeleton = walk.skeleton
    assert len(skeleton) == 22 and skeleton.joint_names == walk.joint_names
    assert skeleton.parents == walk.parents and skeleton.channel_names == walk.channel_names


def test_channels_are_the_files_values(walk):
    channels = walk.channels
    assert channels.shape == (195, 132) and channels.dtype == np.float32
    assert walk.channel_names[:4] == [
        "joint_Root.Xposition", "joint_Root.Yposition", "joint_Root.Zposition", "joint_Root.Zrotation",
    ]
    # The first frame, as written in the file.
    lines = SAMPLE.read_text().splitlines()
    first = lines[lines.index(next(l for l in lines if l.startswith("Frame Time"))) + 1]
    np.testing.assert_array_equal(channels[0], np.array(first.split(), dtype=np.float32))
    # A copy: changing it leaves the motion alone.
    channels[:] = 0
    assert walk.channels[0, 4] != 0 or walk.channels[0, 5] != 0 or walk.channels[10].any()


def test_positions_equal_the_cli(walk, cli, tmp_path):
    csv = tmp_path / "positions.csv"
    subprocess.run([cli, "positions", "--csv", str(SAMPLE), "-o", str(csv)], check=True)
    table = np.loadtxt(csv, delimiter=",", skiprows=1)
    theirs = table[:, 2:].astype(np.float32).reshape(len(walk), len(walk.joint_names), 3)
    ours = walk.positions()
    assert ours.shape == (195, 22, 3) and ours.dtype == np.float32
    np.testing.assert_allclose(ours, theirs, rtol=1e-6, atol=1e-4)
    np.testing.assert_allclose(table[:, 1], np.arange(len(walk)) * walk.frame_time, atol=1e-6)


def test_rotation_kinds_agree(walk):
    q = walk.rotations()  # local quaternions, w x y z
    assert q.shape == (195, 22, 4) and q.dtype == np.float32
    np.testing.assert_allclose(np.linalg.norm(q, axis=-1), 1, atol=1e-5)
    w, x, y, z = np.moveaxis(q.astype(np.float64), -1, 0)
    from_quat = np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], -2)
    matrix = walk.rotations("matrix")
    assert matrix.shape == (195, 22, 3, 3)
    np.testing.assert_allclose(matrix, from_quat, atol=1e-5)
    six = walk.rotations("6d")
    assert six.shape == (195, 22, 6)
    np.testing.assert_allclose(six[..., :3], matrix[..., :, 0], atol=1e-6)
    np.testing.assert_allclose(six[..., 3:], matrix[..., :, 1], atol=1e-6)
    expmap = walk.rotations("expmap")
    assert expmap.shape == (195, 22, 3)
    angle = 2 * np.arctan2(np.linalg.norm(q[..., 1:], axis=-1), np.abs(q[..., 0]))
    np.testing.assert_allclose(np.linalg.norm(expmap, axis=-1), angle, atol=1e-4)


def test_global_rotations_carry_the_bones(walk):
    """x_child = x_parent + R_parent t_child: global rotations, local
    translations and positions of the same forward kinematics."""
    positions = walk.positions().astype(np.float64)
    rotations = walk.rotations("matrix", space="global").astype(np.float64)
    translations = walk.translations().astype(np.float64)
    for j, p in enumerate(walk.parents):
        if p < 0:
            np.testing.assert_allclose(positions[:, j], translations[:, j], atol=1e-3)
            continue
        carried = positions[:, p] + np.einsum("fij,fj->fi", rotations[:, p], translations[:, j])
        np.testing.assert_allclose(positions[:, j], carried, atol=1e-2)
    # The root's global rotation is its local one.
    np.testing.assert_allclose(
        walk.rotations("quat", "global")[:, 0], walk.rotations("quat", "local")[:, 0], atol=1e-6
    )


def test_from_arrays_round_trip(walk):
    q = walk.rotations("quat")
    root = walk.positions()[:, 0]
    rebuilt = mocap.Motion.from_arrays(walk, q, root, walk.frame_time, translations=walk.translations())
    assert rebuilt.joint_names == walk.joint_names and len(rebuilt) == len(walk)
    np.testing.assert_allclose(rebuilt.positions(), walk.positions(), atol=1e-3)
    # From a Skeleton, from float64 arrays, and with q and -q alike.
    again = mocap.Motion.from_arrays(
        walk.skeleton, -q.astype(np.float64), root.astype(np.float64), walk.frame_time,
        translations=walk.translations(),
    )
    np.testing.assert_allclose(again.positions(), walk.positions(), atol=1e-3)
    # Euler angles continuous, as the file's: no 360-degree jumps.
    rotation_columns = [i for i, n in enumerate(walk.channel_names) if n.endswith("rotation")]
    jumps = np.abs(np.diff(rebuilt.channels[:, rotation_columns], axis=0))
    assert jumps.max() < 90


def test_from_arrays_root_only_rig_rests_other_joints(walk):
    """Without translations, joints with position channels take their rest offsets."""
    frames = 3
    q = np.zeros((frames, 22, 4), np.float32)
    q[..., 0] = 1
    root = np.array([[0, 0, 0], [1, 2, 3], [4, 5, 6]], np.float32)
    rest = mocap.Motion.from_arrays(walk.skeleton, q, root, 0.01)
    assert rest.fps == pytest.approx(100)
    p = rest.positions()
    np.testing.assert_allclose(p[:, 0], root)
    np.testing.assert_allclose(p[1, 1], root[1] + walk.offsets[1], atol=1e-5)


def test_write_then_read_gives_the_same_channels(walk, tmp_path):
    out = tmp_path / "out.bvh"
    walk.write(out)
    back = mocap.read(str(out))
    assert back.joint_names == walk.joint_names
    assert back.frame_time == pytest.approx(walk.frame_time)
    np.testing.assert_allclose(back.channels, walk.channels, rtol=1e-6, atol=1e-4)


@pytest.mark.parametrize("extension", ["glb", "gltf"])
def test_gltf_written_and_read_back_gives_the_same_positions(walk, tmp_path, extension):
    out = tmp_path / f"walk.{extension}"
    walk.write(out)
    assert out.read_bytes()[:4] == (b"glTF" if extension == "glb" else b"{\n  ")
    back = mocap.read(str(out))
    assert back.joint_names == walk.joint_names and len(back) == len(walk)
    assert back.channel_names == walk.channel_names
    # Centimetres in the file's record, metres in the glTF: the same joints
    # to 0.1 mm (0.01 cm).
    np.testing.assert_allclose(back.positions(), walk.positions(), atol=0.01)


def test_slicing(walk):
    part = walk[10:100]
    assert len(part) == 90
    np.testing.assert_array_equal(part.channels, walk.channels[10:100])
    np.testing.assert_array_equal(part.positions(), walk.positions()[10:100])
    np.testing.assert_array_equal(walk[-5:].channels, walk.channels[-5:])
    np.testing.assert_array_equal(walk[:].channels, walk.channels)
    assert len(walk[:1000]) == len(walk)
    with pytest.raises(mocap.MocapError, match="contiguous"):
        walk[::2]
    with pytest.raises(mocap.MocapError, match="empty"):
        walk[50:50]
    with pytest.raises(TypeError):
        walk[3]


def test_missing_file():
    with pytest.raises(FileNotFoundError, match="no-such-take.bvh"):
        mocap.read("no-such-take.bvh")
    with pytest.raises(OSError):
        mocap.read("no-such-take.bvh")


def test_malformed_bvh_names_file_line_and_column(tmp_path):
    bad = tmp_path / "bad.bvh"
    text = SAMPLE.read_text().splitlines()
    text[4] = "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Qrotation"
    bad.write_text("\n".join(text) + "\n")
    with pytest.raises(mocap.MocapError) as caught:
        mocap.read(bad)
    assert isinstance(caught.value, ValueError)
    assert re.search(re.escape(str(bad)) + r":5:\d+: ", str(caught.value)), str(caught.value)


def test_unknown_file_type(tmp_path):
    path = tmp_path / "take.xyz"
    path.write_text("x")
    with pytest.raises(mocap.MocapError, match="expected .bvh"):
        mocap.read(path)


def test_wrong_array_shapes(walk):
    q = walk.rotations()
    root = walk.positions()[:, 0]
    with pytest.raises(mocap.MocapError, match=r"rotations must have the shape \(frames, 22, 4\)"):
        mocap.Motion.from_arrays(walk, q[..., :3], root, walk.frame_time)
    with pytest.raises(mocap.MocapError, match="rotations must have the shape"):
        mocap.Motion.from_arrays(walk, q[:, :5], root, walk.frame_time)
    with pytest.raises(mocap.MocapError, match=r"root_positions must have the shape \(195, 3\)"):
        mocap.Motion.from_arrays(walk, q, root[:10], walk.frame_time)
    with pytest.raises(mocap.MocapError, match="translations must have the shape"):
        mocap.Motion.from_arrays(walk, q, root, walk.frame_time, translations=root)
    with pytest.raises(mocap.MocapError, match="not a rotation"):
        mocap.Motion.from_arrays(walk, np.zeros_like(q), root, walk.frame_time)
    with pytest.raises(mocap.MocapError, match="frame time"):
        mocap.Motion.from_arrays(walk, q, root, 0.0)
    with pytest.raises(TypeError, match="Motion or a mocap.Skeleton"):
        mocap.Motion.from_arrays("walk", q, root, walk.frame_time)


def test_unknown_rotation_kind_and_space(walk):
    with pytest.raises(mocap.MocapError, match="unknown rotation kind"):
        walk.rotations("euler")
    with pytest.raises(mocap.MocapError, match="unknown rotation space"):
        walk.rotations("quat", space="world")


def test_positions_release_the_gil():
    """Another Python thread runs while a long call works in Rust."""
    take = mocap.read(SAMPLE)
    long_take = mocap.resample(take, 3000)  # about 19,500 frames
    done = threading.Event()
    ticks = 0

    def work():
        for _ in range(20):
            long_take.positions()
        done.set()

    thread = threading.Thread(target=work)
    start = time.perf_counter()
    thread.start()
    while not done.is_set():
        ticks += 1
        time.sleep(0)
    thread.join()
    assert time.perf_counter() - start > 0.01
    assert ticks > 100, f"the main thread ran {ticks} times while positions() worked"


def test_read_asf_amc(shared):
    folder = shared / "hdm05-sample"
    asf, amc = folder / "HDM_bd.asf", folder / "HDM_bd_depositFloorR_001_120.amc"
    both = mocap.read(asf, amc)
    beside = mocap.read(amc)
    assert len(both) > 100 and both.fps == pytest.approx(120)
    np.testing.assert_array_equal(both.channels, beside.channels)
    assert both.positions().shape == (len(both), len(both.joint_names), 3)
    # A rig whose only root moves: from_arrays without translations is exact.
    rebuilt = mocap.Motion.from_arrays(both, both.rotations(), both.positions()[:, 0], both.frame_time)
    np.testing.assert_allclose(rebuilt.positions(), both.positions(), atol=1e-3)


def test_other_rigs_and_parser_cases(shared):
    for path in sorted((shared / "parser-cases").glob("*.bvh"))[:6] + [shared / "other-rigs/cmu-asf/16_01.bvh"]:
        m = mocap.read(path)
        p = m.positions()
        assert p.shape == (len(m), len(m.joint_names), 3), path
        assert np.isfinite(p).all(), path


def test_bandai_takes_match_the_cli(shared, cli):
    for path in sorted((shared / "bandai" / "dataset-2").glob("*.bvh"))[:3]:
        out = subprocess.run([cli, "positions", "--csv", str(path)], check=True, capture_output=True)
        table = np.loadtxt(out.stdout.decode().splitlines()[1:], delimiter=",")
        m = mocap.read(path)
        np.testing.assert_allclose(
            m.positions().reshape(len(m), -1), table[:, 2:].astype(np.float32), rtol=1e-6, atol=1e-4
        )


def test_proud_sample_reads(walk):
    proud = mocap.read(PROUD)
    assert proud.joint_names == walk.joint_names
