"""mocap.batch on Ray: outputs equal to the single-machine path, the manifest,
resume, bad takes and bad inputs, a real two-node local cluster (``ray
start``) and a worker node killed mid-run. Skipped when Ray is not installed
(tests/python/run.sh installs it)."""

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

import mocap

ray = pytest.importorskip("ray")
import mocap.batch as batch  # noqa: E402

from conftest import PROUD, SAMPLE  # noqa: E402

FILTER = "butterworth:2:6"
BANDAI_TAKES = ["dataset-1_bow_active_001.bvh", "dataset-1_bow_sad_001.bvh", "dataset-1_bow_old_001.bvh"]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def short_tmp(prefix: str) -> str:
    # Ray's socket paths must stay under the 107-byte limit of Unix sockets.
    return tempfile.mkdtemp(prefix=prefix, dir="/tmp")


@pytest.fixture(scope="module")
def local_ray():
    """A local Ray of 2 CPUs in this process, kept between tests (each
    batch call uses it rather than starting its own)."""
    tmp = short_tmp("mray")
    ray.init(num_cpus=2, include_dashboard=False, logging_level="WARNING", _temp_dir=tmp)
    yield
    ray.shutdown()
    shutil.rmtree(tmp, ignore_errors=True)


def make_tree(root: Path) -> list[Path]:
    """Two samples at the top and copies in a subfolder: a tree to mirror."""
    (root / "sub" / "deeper").mkdir(parents=True)
    takes = [root / SAMPLE.name, root / PROUD.name, root / "sub" / "a.bvh", root / "sub" / "deeper" / "b.bvh"]
    for src, dst in zip([SAMPLE, PROUD, SAMPLE, PROUD], takes):
        shutil.copy(src, dst)
    return takes


def manifest_lines(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text().splitlines()]


def reference_clean(take: Path, out: Path, **kw) -> bytes:
    mocap.clean(mocap.read(take), **kw).write(out)
    return out.read_bytes()


def test_clean_equals_single_machine_and_cli(local_ray, tmp_path, cli):
    takes = make_tree(tmp_path / "in")
    result = batch.clean(tmp_path / "in", tmp_path / "out", filter=FILTER, progress=False)
    assert (result.total, result.done, result.failed, result.skipped) == (4, 4, 0, 0)
    records = manifest_lines(tmp_path / "out" / "manifest.jsonl")
    assert sorted(r["input"] for r in records) == sorted(str(t.resolve()) for t in takes)
    for take in takes:
        rel = take.relative_to(tmp_path / "in")
        out = tmp_path / "out" / rel
        rec = next(r for r in records if r["input"] == str(take.resolve()))
        assert rec["status"] == "done" and rec["output"] == str(out) and rec["error"] is None
        assert rec["frames"] == len(mocap.read(take)) and rec["seconds"] >= 0
        assert 0 < rec["value"] < 5  # mean rotation change, degrees
        assert out.read_bytes() == reference_clean(take, tmp_path / "ref.bvh", filter=FILTER), rel
    # The CLI's `mocap clean apply` writes the same bytes.
    for take in takes[:2]:
        subprocess.run([cli, "clean", "apply", "-q", "--filter", FILTER, "-o", str(tmp_path / "cli.bvh"), str(take)],
                       check=True)
        assert (tmp_path / "cli.bvh").read_bytes() == (tmp_path / "out" / take.name).read_bytes()


def test_clean_shipped_model(local_ray, tmp_path):
    (tmp_path / "in").mkdir()
    mocap.read(SAMPLE)[:80].write(tmp_path / "in" / "short.bvh")
    result = batch.clean([tmp_path / "in" / "short.bvh"], tmp_path / "out", progress=False)
    assert result.done == 1
    ref = reference_clean(tmp_path / "in" / "short.bvh", tmp_path / "ref.bvh")
    assert (tmp_path / "out" / "short.bvh").read_bytes() == ref


def test_bandai_takes_and_list_file(local_ray, tmp_path, shared):
    folder = shared / "bandai" / "dataset-1"
    if not folder.is_dir():
        pytest.skip(f"{folder} not found")
    listing = tmp_path / "takes.txt"
    listing.write_text("# three Bandai takes\n" + "".join(f"{folder / n}\n" for n in BANDAI_TAKES))
    result = batch.clean(listing, tmp_path / "out", filter=FILTER, progress=False)
    assert (result.done, result.failed) == (3, 0)
    for name in BANDAI_TAKES:
        ref = reference_clean(folder / name, tmp_path / "ref.bvh", filter=FILTER)
        assert (tmp_path / "out" / name).read_bytes() == ref, name


@pytest.mark.parametrize("to", ["glb", "bvh"])
def test_convert_equals_single_machine(local_ray, tmp_path, to):
    make_tree(tmp_path / "in")
    pattern = str(tmp_path / "in" / "**" / "*.bvh")
    result = batch.convert(pattern, tmp_path / "out", to=to, fps=60, mirror=True, progress=False)
    assert (result.done, result.failed) == (4, 0)
    for take in (tmp_path / "in").rglob("*.bvh"):
        out = (tmp_path / "out" / take.relative_to(tmp_path / "in")).with_suffix("." + to)
        # glTF names its animation after the file: the reference has the same name.
        ref = tmp_path / "ref" / out.name
        ref.parent.mkdir(exist_ok=True)
        mocap.mirror(mocap.resample(mocap.read(take), 60)).write(ref)
        assert out.read_bytes() == ref.read_bytes(), out
    rec = manifest_lines(tmp_path / "out" / "manifest.jsonl")[0]
    assert rec["metric"] == "frames" and rec["value"] == rec["frames"] > 0


def test_index_equals_the_cli_byte_for_byte(local_ray, tmp_path, shared, cli):
    # Bandai takes of several contents, labelled from their names; the
    # features computed by Ray tasks, the forest trained once.
    folder = shared / "bandai" / "dataset-1"
    if not folder.is_dir():
        pytest.skip(f"{folder} not found")
    clips = tmp_path / "clips"
    clips.mkdir()
    for take in sorted(folder.glob("*.bvh"))[::20][:8]:
        shutil.copy(take, clips / take.name)
    shutil.copy(SAMPLE, clips / SAMPLE.name)
    broken = clips / "dataset-1_walk_broken_001.bvh"
    broken.write_text(SAMPLE.read_text()[:2000])
    ours = tmp_path / "batch.idx"
    result = batch.index(clips, ours, labels_from_name="bandai-content", trees=12,
                         progress=False)
    # The broken clip is recorded, the others indexed.
    count = len(list(clips.glob("*.bvh")))
    assert count >= 8
    assert (result.total, result.done, result.failed) == (count, count - 1, 1), result.errors
    assert result.errors[0][0] == str(broken) and "MocapError" in result.errors[0][1]
    records = manifest_lines(result.manifest)
    assert sorted(r["status"] for r in records) == ["done"] * (count - 1) + ["error"]
    # The command on the same clips (without the broken one) writes the same file.
    broken.unlink()
    theirs = tmp_path / "cli.idx"
    subprocess.run([cli, "search", "index", str(clips), "--labels-from-name", "bandai-content",
                    "--trees", "12", "-o", str(theirs), "-q"], check=True)
    assert ours.read_bytes() == theirs.read_bytes()
    # And the index answers queries.
    report = mocap.search.Index.load(ours).query(mocap.read(SAMPLE), top=3)
    assert len(report.matches) == 3


def test_index_bad_inputs_fail_before_any_work(tmp_path):
    (tmp_path / "empty").mkdir()
    with pytest.raises(batch.BatchError, match="no clips"):
        batch.index(tmp_path / "empty", tmp_path / "x.idx", labels_from_name="bandai-content")
    with pytest.raises(batch.BatchError, match="labels"):
        batch.index(SAMPLE, tmp_path / "x.idx")
    assert not (tmp_path / "x.idx").exists()


def test_asf_amc_takes(local_ray, tmp_path, shared):
    # An AMC take is read with the ASF skeleton beside it, as `mocap.read` does.
    folder = shared / "hdm05-sample"
    if not folder.is_dir():
        pytest.skip(f"{folder} not found")
    amc = folder / "HDM_bd_depositFloorR_001_120.amc"
    result = batch.convert(folder, tmp_path / "out", to="bvh", progress=False)
    assert (result.total, result.done, result.failed) == (1, 1, 0), result.errors
    ref = tmp_path / "ref" / "HDM_bd_depositFloorR_001_120.bvh"
    ref.parent.mkdir()
    mocap.read(amc).write(ref)
    assert (tmp_path / "out" / ref.name).read_bytes() == ref.read_bytes()
    result = batch.clean(amc, tmp_path / "clean", filter=FILTER, progress=False)
    assert result.done == 1, result.errors
    # Cleaned takes are written as BVH (a/b.amc -> OUT/a/b.bvh).
    cleaned = tmp_path / "clean" / ref.name
    assert cleaned.read_bytes() == reference_clean(amc, tmp_path / "ref" / "clean.bvh", filter=FILTER)


def test_bad_take_recorded_and_others_finish(local_ray, tmp_path):
    takes = make_tree(tmp_path / "in")
    bad = tmp_path / "in" / "sub" / "truncated.bvh"
    bad.write_bytes(PROUD.read_bytes()[:3000])
    result = batch.clean(tmp_path / "in", tmp_path / "out", filter=FILTER, progress=False)
    assert (result.total, result.done, result.failed) == (5, 4, 1)
    assert result.errors[0][0] == str(bad.resolve())
    records = manifest_lines(tmp_path / "out" / "manifest.jsonl")
    errors = [r for r in records if r["status"] == "error"]
    assert len(records) == 5 and len(errors) == 1
    assert errors[0]["input"] == str(bad.resolve())
    assert "MocapError" in errors[0]["error"] and "truncated.bvh:" in errors[0]["error"]
    assert not (tmp_path / "out" / "sub" / "truncated.bvh").exists()
    for take in takes:
        assert (tmp_path / "out" / take.relative_to(tmp_path / "in")).is_file()


def test_resume_skips_done_takes(local_ray, tmp_path):
    make_tree(tmp_path / "in")
    bad = tmp_path / "in" / "bad.bvh"
    bad.write_text("HIERARCHY\n")
    first = batch.clean(tmp_path / "in", tmp_path / "out", filter=FILTER, progress=False)
    assert (first.done, first.failed, first.skipped) == (4, 1, 0)
    outputs = sorted((tmp_path / "out").rglob("*.bvh"))
    mtimes = {p: p.stat().st_mtime_ns for p in outputs}
    # A rerun does only the failed take; then one output is lost and redone.
    second = batch.clean(tmp_path / "in", tmp_path / "out", filter=FILTER, progress=False)
    assert (second.done, second.failed, second.skipped) == (0, 1, 4)
    assert {p: p.stat().st_mtime_ns for p in outputs} == mtimes
    outputs[0].unlink()
    third = batch.clean(tmp_path / "in", tmp_path / "out", filter=FILTER, progress=False)
    assert (third.done, third.failed, third.skipped) == (1, 1, 3)
    assert outputs[0].is_file()
    records = manifest_lines(tmp_path / "out" / "manifest.jsonl")
    assert [r["status"] for r in records].count("done") == 5
    assert [r["status"] for r in records].count("error") == 3
    # resume=False redoes everything.
    fourth = batch.clean(tmp_path / "in", tmp_path / "out", filter=FILTER, progress=False, resume=False)
    assert (fourth.done, fourth.skipped) == (4, 0)


def run_cli(*args, env=None, timeout=120):
    return subprocess.run([sys.executable, "-m", "mocap.batch", *map(str, args)], capture_output=True,
                          text=True, env=env, timeout=timeout)


def test_bad_inputs_fail_before_any_work(tmp_path):
    make_tree(tmp_path / "in")
    (tmp_path / "empty").mkdir()
    with pytest.raises(batch.BatchError, match=r"no takes found in .*empty"):
        batch.clean(tmp_path / "empty", tmp_path / "out", filter=FILTER)
    with pytest.raises(batch.BatchError, match="no such file or folder"):
        batch.clean(tmp_path / "missing", tmp_path / "out", filter=FILTER)
    (tmp_path / "afile").write_text("")
    with pytest.raises(batch.BatchError, match="output folder cannot be written"):
        batch.clean(tmp_path / "in", tmp_path / "afile" / "out", filter=FILTER)
    with pytest.raises(batch.BatchError, match="unknown output format"):
        batch.convert(tmp_path / "in", tmp_path / "out", to="fbx")
    assert not (tmp_path / "out").exists()
    # The command line: exit code 1, the message on stderr, nothing written.
    port = free_port()  # nothing listens there
    start = time.monotonic()
    r = run_cli("clean", tmp_path / "in", "-o", tmp_path / "out", "--filter", FILTER, "--address", f"127.0.0.1:{port}")
    assert r.returncode == 1, r.stderr
    assert f"cannot reach the Ray cluster at 127.0.0.1:{port}" in r.stderr
    assert time.monotonic() - start < 30
    r = run_cli("convert", tmp_path / "empty", "-o", tmp_path / "out", "--to", "glb")
    assert r.returncode == 1 and "no takes found" in r.stderr
    assert not (tmp_path / "out" / "manifest.jsonl").exists()


# ---------------------------------------------------------------- a real cluster


@pytest.fixture(scope="module")
def cluster():
    """A head node and a worker node of one CPU each, started with `ray
    start` (token authentication, a token of their own), every task slowed
    down by 0.6 s and recording its process: the last tests kill the worker
    node. Stopped with `ray stop --force`."""
    if ray.is_initialized():
        ray.shutdown()
    ray_bin = Path(sys.executable).parent / "ray"
    tmp = Path(short_tmp("mcl"))
    pids = tmp / "pids"
    pids.mkdir()
    port, head_nm, worker_nm, client = free_port(), free_port(), free_port(), free_port()
    env = dict(os.environ, RAY_AUTH_MODE="token", RAY_AUTH_TOKEN=os.urandom(16).hex(),
               MOCAP_BATCH_TEST_PIDS=str(pids), MOCAP_BATCH_TEST_DELAY="0.6",
               RAY_health_check_period_ms="500", RAY_health_check_failure_threshold="3",
               RAY_USAGE_STATS_ENABLED="0")
    common = ["--num-cpus=1", "--disable-usage-stats"]
    try:
        subprocess.run([ray_bin, "start", "--head", f"--port={port}", f"--node-manager-port={head_nm}",
                        f"--ray-client-server-port={client}", "--include-dashboard=false",
                        f"--temp-dir={tmp / 'ray'}", *common],
                       env=env, check=True, capture_output=True, timeout=120)
        subprocess.run([ray_bin, "start", f"--address=127.0.0.1:{port}", f"--node-manager-port={worker_nm}",
                        *common], env=env, check=True, capture_output=True, timeout=120)
        yield {"address": f"127.0.0.1:{port}", "client": f"ray://127.0.0.1:{client}", "env": env,
               "pids": pids, "worker_nm": worker_nm}
    finally:
        subprocess.run([ray_bin, "stop", "--force"], env=env, capture_output=True, timeout=120)
        shutil.rmtree(tmp, ignore_errors=True)


def test_cluster_cli(cluster, tmp_path):
    takes = make_tree(tmp_path / "in")
    (tmp_path / "in" / "bad.bvh").write_text("HIERARCHY\nROOT")
    r = run_cli("clean", tmp_path / "in", "-o", tmp_path / "out", "--filter", FILTER,
                "--address", cluster["address"], env=cluster["env"])
    assert r.returncode == 3, r.stderr  # one take failed
    assert "4 done, 0 skipped as done before, 1 failed of 5 takes" in r.stdout
    assert "takes/s, ETA" in r.stderr
    for take in takes:
        ref = reference_clean(take, tmp_path / "ref.bvh", filter=FILTER)
        assert (tmp_path / "out" / take.relative_to(tmp_path / "in")).read_bytes() == ref
    # Both nodes ran takes.
    starts = list(cluster["pids"].glob("start.*"))
    assert len({p.name.split(".")[1] for p in starts}) >= 2
    # Resume: everything done is skipped, the bad take is tried again.
    r = run_cli("clean", tmp_path / "in", "-o", tmp_path / "out", "--filter", FILTER,
                "--address", cluster["address"], "-q", env=cluster["env"])
    assert r.returncode == 3 and "0 done, 4 skipped as done before, 1 failed of 5 takes" in r.stdout


def test_ray_client_address(cluster, tmp_path):
    # A driver that is not on a node: Ray Client (ray://HOST:PORT).
    make_tree(tmp_path / "in")
    r = run_cli("convert", tmp_path / "in", "-o", tmp_path / "out", "--to", "glb",
                "--address", cluster["client"], "-q", env=cluster["env"])
    assert r.returncode == 0, r.stderr
    assert "4 done, 0 skipped as done before, 0 failed of 4 takes" in r.stdout
    for take in (tmp_path / "in").rglob("*.bvh"):
        out = (tmp_path / "out" / take.relative_to(tmp_path / "in")).with_suffix(".glb")
        ref = tmp_path / "ref" / out.name
        ref.parent.mkdir(exist_ok=True)
        mocap.read(take).write(ref)
        assert out.read_bytes() == ref.read_bytes(), out


def worker_raylet(node_manager_port: int) -> int:
    for proc in Path("/proc").iterdir():
        if not proc.name.isdigit():
            continue
        try:
            args = (proc / "cmdline").read_bytes().split(b"\0")
        except OSError:
            continue
        if args and args[0].endswith(b"/raylet") and f"--node_manager_port={node_manager_port}".encode() in args:
            return int(proc.name)
    raise AssertionError(f"no raylet with node manager port {node_manager_port}")


def parent_pid(pid: int) -> int:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return -1
    return int(stat.rsplit(")", 1)[1].split()[1])


def test_killed_worker_node_takes_are_retried(cluster, tmp_path):
    """SIGKILLs a worker process of the worker node while it runs a take, and
    the node's raylet: the node is gone, the take is retried on the head node, the
    manifest holds every take exactly once as done, every output equals the
    single-machine path's."""
    if not Path("/proc/self/stat").exists():
        pytest.skip("needs /proc to find the worker node's raylet")
    src = tmp_path / "in"
    src.mkdir()
    for i in range(10):
        shutil.copy(SAMPLE if i % 2 else PROUD, src / f"take{i:02}.bvh")
    for p in cluster["pids"].iterdir():
        p.unlink()
    raylet = worker_raylet(cluster["worker_nm"])
    proc = subprocess.Popen([sys.executable, "-m", "mocap.batch", "clean", str(src), "-o", str(tmp_path / "out"),
                             "--filter", FILTER, "--address", cluster["address"], "--max-retries", "3"],
                            env=cluster["env"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    killed_take = None
    deadline = time.monotonic() + 60
    try:
        # Wait for a take that started on the worker node and has not finished, after one take is done.
        while killed_take is None and time.monotonic() < deadline:
            manifest = tmp_path / "out" / "manifest.jsonl"
            if manifest.is_file() and manifest.read_text().count("\n") >= 1:
                files = {p.name: p for p in cluster["pids"].iterdir()}
                finished = {(n.split(".")[1], p.read_text()) for n, p in files.items() if n.startswith("finish.")}
                for name, p in files.items():
                    pid = name.split(".")[1]
                    if name.startswith("start.") and parent_pid(int(pid)) == raylet and (pid, p.read_text()) not in finished:
                        killed_take = p.read_text()
                        # The task's process first: a worker outlives its raylet
                        # long enough to finish a take and report it.
                        os.kill(int(pid), signal.SIGKILL)
                        os.kill(raylet, signal.SIGKILL)
                        break
            time.sleep(0.02)
        assert killed_take is not None, "no take ran on the worker node"
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 0, err
    assert "10 done, 0 skipped as done before, 0 failed of 10 takes" in out
    records = manifest_lines(tmp_path / "out" / "manifest.jsonl")
    assert sorted(r["input"] for r in records) == sorted(str(p) for p in src.glob("*.bvh"))
    assert all(r["status"] == "done" for r in records)
    # The killed take started twice: once on the killed node, once again.
    starts = [p.read_text() for p in cluster["pids"].glob("start.*")]
    assert starts.count(killed_take) >= 2, (killed_take, starts)
    refs = {n: reference_clean(n, tmp_path / f"ref{i}.bvh", filter=FILTER) for i, n in enumerate([SAMPLE, PROUD])}
    for i in range(10):
        assert (tmp_path / "out" / f"take{i:02}.bvh").read_bytes() == refs[SAMPLE if i % 2 else PROUD]
    assert not list((tmp_path / "out").glob(".*.tmp")), "a temporary file was left"
