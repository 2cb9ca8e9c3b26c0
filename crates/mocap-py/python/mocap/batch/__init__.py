"""Archive-scale batches on a Ray cluster: clean or convert every take of a
folder tree, a glob or a list file, one Ray task per take.

>>> import mocap.batch
>>> result = mocap.batch.clean("archive/", "cleaned/", filter="butterworth:2:6")
>>> result.done, result.failed, result.manifest
(120, 0, PosixPath('cleaned/manifest.jsonl'))

Ray is an optional dependency: ``pip install "ray[default]"`` beside the
package. Outputs mirror the input tree under the output
folder and are written atomically; a manifest (JSON lines) records every
take as its result arrives, so a rerun resumes where a crash stopped.
See docs/scale.md.
"""

from __future__ import annotations

import glob as _glob
import json
import os
import socket
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable, Literal, Optional, Sequence, Union

__all__ = ["BatchError", "BatchResult", "clean", "convert", "index"]

PathLike = Union[str, "os.PathLike[str]"]
Inputs = Union[PathLike, Sequence[PathLike]]

#: Extensions read as takes; any other file given as an input is a list file
#: (one path per line, relative paths from the list file's folder).
TAKE_EXTENSIONS = (".bvh", ".amc")
#: Extensions accepted when a take is named explicitly (a list file, a glob).
READABLE_EXTENSIONS = (".bvh", ".amc", ".glb", ".gltf")
FORMATS = ("bvh", "glb", "gltf")
#: Retries of a take whose worker process or node died (not of a take that
#: raised an error: those are recorded in the manifest).
DEFAULT_MAX_RETRIES = 3
CONNECT_TIMEOUT_S = 5.0


class BatchError(ValueError):
    """An input the batch cannot start with: no takes found, an output folder
    that cannot be written, an unknown format, an unreachable Ray address.
    Raised before any take is processed."""


@dataclass
class BatchResult:
    """What a batch did. ``errors``: (input, message) of every failed take."""

    total: int
    done: int
    failed: int
    skipped: int
    seconds: float
    manifest: Path
    output_dir: Path
    errors: list[tuple[str, str]] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """Every take is done (processed now or skipped as done before)."""
        return self.failed == 0


# ---------------------------------------------------------------- inputs


def _has_magic(text: str) -> bool:
    return any(c in text for c in "*?[")


def _glob_root(pattern: str) -> Path:
    """The folder before a pattern's first wildcard part."""
    parts = Path(pattern).parts
    fixed = []
    for part in parts:
        if _has_magic(part):
            break
        fixed.append(part)
    return Path(*fixed) if fixed else Path(".")


def _list_file(path: Path) -> list[Path]:
    base = path.parent
    takes = []
    with open(path, encoding="utf-8") as f:
        for line in f:
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            p = Path(line).expanduser()
            takes.append(p if p.is_absolute() else base / p)
    return takes


def _common_root(paths: Sequence[Path]) -> Path:
    return Path(os.path.commonpath([str(p.parent) for p in paths]))


def find_takes(inputs: Inputs) -> list[tuple[Path, Path]]:
    """The takes named by ``inputs`` as (absolute path, path relative to its
    input's root), sorted. ``inputs``: a folder (its .bvh and .amc files,
    recursively), a glob, a take, a list file (one path per line), or a list
    of these. Raises BatchError when no take is found or a named file is
    missing."""
    if isinstance(inputs, (str, os.PathLike)):
        inputs = [inputs]
    found: list[tuple[Path, Path]] = []
    for item in inputs:
        text = os.fspath(item)
        path = Path(text).expanduser()
        if path.is_dir():
            root = path.resolve()
            takes = sorted(
                p for p in root.rglob("*") if p.suffix.lower() in TAKE_EXTENSIONS and p.is_file()
            )
            found += [(p, p.relative_to(root)) for p in takes]
        elif path.is_file():
            if path.suffix.lower() in READABLE_EXTENSIONS:
                p = path.resolve()
                found.append((p, Path(p.name)))
            else:
                listed = _list_file(path)
                missing = [p for p in listed if not p.is_file()]
                if missing:
                    raise BatchError(
                        f"{text}: {len(missing)} listed take(s) not found, first {missing[0]}"
                    )
                listed = [p.resolve() for p in listed]
                if listed:
                    root = _common_root(listed)
                    found += [(p, p.relative_to(root)) for p in sorted(listed)]
        elif _has_magic(text):
            root = _glob_root(text).resolve()
            takes = sorted(
                Path(p).resolve()
                for p in _glob.glob(text, recursive=True)
                if Path(p).is_file() and Path(p).suffix.lower() in READABLE_EXTENSIONS
            )
            found += [(p, p.relative_to(root)) for p in takes]
        else:
            raise BatchError(f"{text}: no such file or folder")
    if not found:
        names = ", ".join(os.fspath(i) for i in inputs) or "(none)"
        raise BatchError(f"no takes found in {names} (looked for .bvh and .amc files)")
    # One take named twice (a folder and a glob) is processed once.
    seen: dict[Path, Path] = {}
    for p, rel in found:
        seen.setdefault(p, rel)
    return sorted(seen.items(), key=lambda t: str(t[1]))


def _check_output_dir(output_dir: Path) -> None:
    try:
        output_dir.mkdir(parents=True, exist_ok=True)
        probe = output_dir / f".mocap-batch-probe.{os.getpid()}"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as e:
        raise BatchError(f"{output_dir}: the output folder cannot be written ({e})") from None


# ---------------------------------------------------------------- Ray


def _import_ray() -> Any:
    try:
        import ray
    except ImportError:
        raise BatchError(
            'mocap.batch needs Ray: pip install "ray[default]" beside mocap (docs/scale.md)'
        ) from None
    return ray


def _check_reachable(address: str) -> None:
    """Fails fast, naming the address, when nothing listens at host:port."""
    hostport = address.split("://", 1)[-1].rstrip("/")
    host, sep, port = hostport.rpartition(":")
    if not sep or not port.isdigit():
        raise BatchError(
            f"{address}: not a Ray address (use local, auto, host:port or ray://host:port)"
        )
    try:
        with socket.create_connection((host.strip("[]"), int(port)), timeout=CONNECT_TIMEOUT_S):
            pass
    except OSError as e:
        raise BatchError(f"cannot reach the Ray cluster at {address}: {e}") from None


def _connect(address: Optional[str], num_cpus: Optional[int]) -> bool:
    """Connects to Ray; True when this call started it (and shuts it down)."""
    ray = _import_ray()
    if address is None and os.environ.get("RAY_ADDRESS"):
        address = os.environ["RAY_ADDRESS"]  # as ray.init() does (a KubeRay job's entrypoint)
    local = address is None or address == "local"
    if ray.is_initialized():
        if local:
            return False  # the caller's own ray.init: use it
        raise BatchError(
            f"Ray is already initialized in this process; cannot connect to {address} "
            "(call ray.shutdown() first, or pass address=None to use it)"
        )
    kwargs: dict[str, Any] = dict(
        include_dashboard=False, logging_level="WARNING", log_to_driver=True
    )
    if local:
        ray.init(num_cpus=num_cpus, **kwargs)
        return True
    if address != "auto":
        _check_reachable(address)
    try:
        ray.init(address=address, **kwargs)
    except Exception as e:  # ConnectionError, grpc errors, a missing cluster for "auto"
        hint = ""
        if not os.environ.get("RAY_AUTH_MODE"):
            hint = (" (a cluster with token authentication needs RAY_AUTH_MODE=token and its"
                    " token on this machine too: docs/scale.md)")
        raise BatchError(f"cannot connect to the Ray cluster at {address}: {e}{hint}") from None
    return True


# ---------------------------------------------------------------- per take


def _test_hook(stage: str, source: str) -> None:
    """Tests only: with ``MOCAP_BATCH_TEST_PIDS`` (a folder), every task start
    and finish leaves a file there naming its process and take; with
    ``MOCAP_BATCH_TEST_DELAY`` (seconds), every take is that much slower."""
    folder = os.environ.get("MOCAP_BATCH_TEST_PIDS")
    if folder:
        name = f"{stage}.{os.getpid()}.{time.monotonic_ns()}"
        Path(folder, name).write_text(source)
    delay = float(os.environ.get("MOCAP_BATCH_TEST_DELAY") or 0)
    if delay and stage == "start":
        time.sleep(delay)


def _one_thread_per_task() -> None:
    """A task reserves one CPU, but mocap's Rust code runs on rayon, whose
    pool takes every core of the node: with a task per core, the threads
    would oversubscribe the node (a Bandai take cleaned with 2 threads costs
    1.29 CPU-seconds, with 1 thread 1.06). Ray does the same for OpenMP
    (OMP_NUM_THREADS). The pool reads RAYON_NUM_THREADS when a process
    first uses it; a value set for the cluster is kept. The results do not
    depend on the number of threads (the tests compare them byte for byte
    with the caller's)."""
    os.environ.setdefault("RAYON_NUM_THREADS", "1")


def _mean_rotation_change(before: Any, after: Any) -> Optional[float]:
    """Mean absolute change of the rotation channels, in degrees."""
    import numpy as np

    if before.channel_names != after.channel_names or len(before) != len(after):
        return None
    cols = [i for i, n in enumerate(before.channel_names) if n.endswith("rotation")]
    if not cols or len(before) == 0:
        return None
    diff = np.abs(after.channels[:, cols].astype(np.float64) - before.channels[:, cols])
    return float(diff.mean())


def process_take(op: str, source: str, target: str, options: dict[str, Any]) -> dict[str, Any]:
    """Reads ``source``, cleans or converts it and writes ``target``
    (atomically, through Motion.write). Returns a manifest record; an error
    is returned in it, not raised. What each Ray task runs."""
    import mocap

    _one_thread_per_task()
    start = time.perf_counter()
    record: dict[str, Any] = {"input": source, "output": target, "status": "error"}
    try:
        _test_hook("start", source)
        motion = mocap.read(source)
        if op == "clean":
            out = mocap.clean(motion, model=options.get("model"), filter=options.get("filter"))
            metric = _mean_rotation_change(motion, out)
            record["metric"] = "mean_rotation_change_deg"
            record["value"] = None if metric is None else round(metric, 6)
        elif op == "convert":
            out = motion
            if options.get("fps"):
                out = mocap.resample(out, float(options["fps"]))
            if options.get("mirror"):
                out = mocap.mirror(out)
            record["metric"] = "frames"
            record["value"] = len(out)
        else:
            raise ValueError(f"unknown operation {op!r}")
        Path(target).parent.mkdir(parents=True, exist_ok=True)
        out.write(target)
        record.update(status="done", error=None, frames=len(out))
        _test_hook("finish", source)
    except Exception as e:
        record.update(error=f"{type(e).__name__}: {e}", frames=None)
    record["seconds"] = round(time.perf_counter() - start, 4)
    return record


# ---------------------------------------------------------------- driver


def read_manifest(path: PathLike) -> dict[str, dict[str, Any]]:
    """The last record of every input in a manifest (missing file: empty).
    A torn last line (a crash while writing it) is ignored."""
    records: dict[str, dict[str, Any]] = {}
    try:
        f = open(path, encoding="utf-8")
    except FileNotFoundError:
        return records
    with f:
        for line in f:
            try:
                rec = json.loads(line)
            except json.JSONDecodeError:
                continue
            if isinstance(rec, dict) and "input" in rec:
                records[rec["input"]] = rec
    return records


class _Progress:
    def __init__(self, op: str, total: int, skipped: int, enabled: bool):
        self.op, self.total, self.skipped, self.enabled = op, total, skipped, enabled
        self.start = time.monotonic()
        self.last = 0.0
        self.done = self.failed = 0

    def update(self, force: bool = False) -> None:
        now = time.monotonic()
        if not self.enabled or (not force and now - self.last < 1.0):
            return
        self.last = now
        finished = self.done + self.failed
        todo = self.total - self.skipped
        elapsed = now - self.start
        rate = finished / elapsed if elapsed > 0 else 0.0
        eta = f"{(todo - finished) / rate:.0f} s" if rate > 0 else "?"
        print(
            f"mocap.batch {self.op}: {finished + self.skipped}/{self.total} takes"
            f" ({self.failed} failed, {self.skipped} skipped as done),"
            f" {rate:.2f} takes/s, ETA {eta}",
            file=sys.stderr,
            flush=True,
        )


def _run(
    op: str,
    inputs: Inputs,
    output_dir: PathLike,
    suffix: Optional[str],
    options: dict[str, Any],
    address: Optional[str],
    manifest: Optional[PathLike],
    progress: bool,
    num_cpus: Optional[int],
    max_retries: int,
    resume: bool,
) -> BatchResult:
    start = time.perf_counter()
    # Everything that can be wrong is checked before any take is processed.
    takes = find_takes(inputs)
    out_root = Path(output_dir).expanduser().resolve()
    _check_output_dir(out_root)
    manifest_path = Path(manifest).expanduser() if manifest else out_root / "manifest.jsonl"
    _check_output_dir(manifest_path.parent.resolve())
    for key in ("model",):
        if options.get(key) and not Path(options[key]).is_file():
            raise BatchError(f"{options[key]}: no such model file")

    jobs: list[tuple[str, str]] = []
    targets: dict[str, str] = {}
    for path, rel in takes:
        target = out_root / (rel.with_suffix(suffix) if suffix else rel)
        if target.resolve() == path:
            raise BatchError(f"{path}: the output would overwrite its input; choose another folder")
        if str(target) in targets:
            raise BatchError(
                f"{path} and {targets[str(target)]} would both be written to {target}"
            )
        targets[str(target)] = str(path)
        jobs.append((str(path), str(target)))

    previous = read_manifest(manifest_path) if resume else {}
    todo = []
    for source, target in jobs:
        rec = previous.get(source)
        if (
            rec
            and rec.get("status") == "done"
            and rec.get("output") == target
            and Path(target).is_file()
        ):
            continue
        todo.append((source, target))
    skipped = len(jobs) - len(todo)

    owned = _connect(address, num_cpus) if todo else False
    result = BatchResult(
        total=len(jobs), done=0, failed=0, skipped=skipped, seconds=0.0,
        manifest=manifest_path, output_dir=out_root,
    )
    bar = _Progress(op, len(jobs), skipped, progress)
    try:
        if todo:
            jobs = [({"input": src, "output": dst}, (op, src, dst, options)) for src, dst in todo]
            with open(manifest_path, "a", encoding="utf-8") as log:
                _drive(op, process_take, jobs, log, max_retries, result, bar)
    finally:
        if owned:
            _import_ray().shutdown()
    bar.update(force=True)
    result.seconds = time.perf_counter() - start
    return result


def _drive(
    op: str,
    function: Any,
    jobs: list[tuple[dict[str, Any], tuple]],
    log: Any,
    max_retries: int,
    result: BatchResult,
    bar: _Progress,
    keep: Optional[Any] = None,
) -> None:
    """Runs ``function(*args)`` as one Ray task per ``(record, args)`` of
    ``jobs``; each returns its manifest record. ``record`` (the input, and
    the output if any) starts the error record of a task whose retries ran
    out. Each record is written to ``log`` as it arrives and counted in
    ``result`` and ``bar``; ``keep(record)`` sees every record that is done
    before it is written (to take what is not for the manifest out of it)."""
    ray = _import_ray()
    task = ray.remote(num_cpus=1, max_retries=max_retries)(function)
    # Bounded in-flight tasks: an archive of 100,000 takes is not submitted at once.
    window = max(16, 4 * int(ray.cluster_resources().get("CPU", 1)))
    pending: dict[Any, dict[str, Any]] = {}
    queue = iter(jobs)
    while True:
        while len(pending) < window:
            job = next(queue, None)
            if job is None:
                break
            pending[task.remote(*job[1])] = job[0]
        if not pending:
            break
        ready, _ = ray.wait(list(pending), num_returns=1, timeout=1.0)
        for ref in ready:
            base = pending.pop(ref)
            try:
                rec = ray.get(ref)
            except Exception as e:  # the task's retries ran out (a node died each time)
                rec = {
                    **base, "status": "error",
                    "error": f"{type(e).__name__}: {e}".splitlines()[0],
                    "frames": None, "seconds": None,
                }
            rec["op"] = op
            if rec["status"] == "done":
                if keep:
                    keep(rec)
                result.done += 1
                bar.done += 1
            else:
                result.failed += 1
                bar.failed += 1
                result.errors.append((base["input"], rec.get("error") or ""))
            log.write(json.dumps(rec) + "\n")
            log.flush()
        bar.update()


def clean(
    inputs: Inputs,
    output_dir: PathLike,
    *,
    model: Optional[PathLike] = None,
    filter: Optional[str] = None,
    address: Optional[str] = None,
    manifest: Optional[PathLike] = None,
    progress: bool = True,
    num_cpus: Optional[int] = None,
    max_retries: int = DEFAULT_MAX_RETRIES,
    resume: bool = True,
) -> BatchResult:
    """Cleans every take of ``inputs`` as ``mocap.clean(mocap.read(take),
    model, filter)`` and writes it as BVH under ``output_dir``, mirroring the
    input tree (``a/b.amc`` -> ``OUT/a/b.bvh``), one Ray task per take.

    inputs: a folder (its .bvh and .amc files, recursively), a glob, a take,
        a list file (one path per line), or a list of these.
    model, filter: as mocap.clean (default: the shipped model).
    address: None or "local" starts Ray on this machine (``num_cpus`` CPUs,
        default all) unless this process already called ray.init; "auto",
        "host:port" or "ray://host:port" joins a running cluster. None with
        $RAY_ADDRESS set joins that cluster, as ray.init() does.
    manifest: the JSON-lines record of every take (default
        ``OUTPUT_DIR/manifest.jsonl``); takes it says are done, whose output
        exists, are skipped (``resume=False`` redoes them).
    max_retries: retries of a take whose worker or node died.

    Raises BatchError before any work when no take is found, the output
    folder cannot be written or the cluster cannot be reached. A take that
    fails is recorded in the manifest and does not stop the others.
    """
    options = {"model": os.fspath(model) if model else None, "filter": filter}
    return _run(
        "clean", inputs, output_dir, ".bvh", options, address, manifest, progress,
        num_cpus, max_retries, resume,
    )


def convert(
    inputs: Inputs,
    output_dir: PathLike,
    *,
    to: Literal["bvh", "glb", "gltf"] = "bvh",
    fps: Optional[float] = None,
    mirror: bool = False,
    address: Optional[str] = None,
    manifest: Optional[PathLike] = None,
    progress: bool = True,
    num_cpus: Optional[int] = None,
    max_retries: int = DEFAULT_MAX_RETRIES,
    resume: bool = True,
) -> BatchResult:
    """Converts every take of ``inputs`` to ``to`` (BVH, or glTF: .glb,
    .gltf), resampled to ``fps`` frames per second when given and mirrored
    when ``mirror``, under ``output_dir``, mirroring the input tree. Other
    arguments as :func:`clean`."""
    if to not in FORMATS:
        raise BatchError(f"unknown output format {to!r} (bvh, glb or gltf)")
    if fps is not None and not fps > 0:
        raise BatchError(f"fps must be positive, not {fps}")
    options = {"fps": fps, "mirror": bool(mirror)}
    return _run(
        "convert", inputs, output_dir, "." + to, options, address, manifest, progress,
        num_cpus, max_retries, resume,
    )


# ---------------------------------------------------------------- index


def clip_features(path: str) -> dict[str, Any]:
    """One clip's pose features for a search index (what each Ray task of
    :func:`index` runs). An error is returned in the record, not raised."""
    from mocap import _mocap

    _one_thread_per_task()
    start = time.perf_counter()
    record: dict[str, Any] = {"input": path, "status": "error", "op": "index"}
    try:
        _test_hook("start", path)
        values, fps = _mocap.search_features(path)
        record.update(status="done", error=None, frames=int(values.shape[0]),
                      values=values, fps=fps)
        _test_hook("finish", path)
    except Exception as e:
        record.update(error=f"{type(e).__name__}: {e}", frames=None)
    record["seconds"] = round(time.perf_counter() - start, 4)
    return record


def index(
    inputs: Union[PathLike, Sequence[PathLike]],
    output: PathLike,
    *,
    labels: Optional[PathLike] = None,
    labels_from_name: Optional[str] = None,
    trees: int = 100,
    candidates: int = 64,
    min_entropy: float = 0.0,
    frames: int = 10,
    seed: int = 1,
    bootstrap: bool = True,
    address: Optional[str] = None,
    progress: bool = True,
    num_cpus: Optional[int] = None,
    max_retries: int = DEFAULT_MAX_RETRIES,
) -> BatchResult:
    """Builds a search index of the clips of ``inputs`` (files and folders,
    as ``mocap search index`` takes them) and writes it to ``output``: each
    clip's pose features are computed by a Ray task, the forest is trained
    once on this machine. Labels come from a label file (``labels``) or a
    file-name pattern or preset (``labels_from_name``, e.g.
    "bandai-content"); the forest settings are the command's. The same
    inputs and settings give the same file as ``mocap search index``, byte
    for byte.

    A clip that cannot be read is recorded in the manifest
    (``OUTPUT.manifest.jsonl``, one line per clip) and left out of the
    index. Raises BatchError before any work when the labels cannot be
    found, no clip is found, or ``output`` cannot be written."""
    from mocap import _mocap

    start = time.perf_counter()
    given = [inputs] if isinstance(inputs, (str, os.PathLike)) else list(inputs)
    try:
        clips, rule_name = _mocap.search_clips(
            [os.fspath(p) for p in given],
            os.fspath(labels) if labels else None,
            labels_from_name,
        )
    except (ValueError, OSError) as e:
        raise BatchError(str(e)) from e
    if not clips:
        raise BatchError(f"no clips (.bvh, .amc) found in {', '.join(map(os.fspath, given))}")
    output = Path(output).expanduser()
    _check_output_dir(output.parent.resolve())
    manifest_path = output.with_name(output.name + ".manifest.jsonl")

    owned = _connect(address, num_cpus)
    result = BatchResult(total=len(clips), done=0, failed=0, skipped=0, seconds=0.0,
                         manifest=manifest_path, output_dir=output.parent)
    bar = _Progress("index", len(clips), 0, progress)
    features: dict[str, tuple[Any, float]] = {}

    def keep(rec: dict[str, Any]) -> None:
        features[rec["input"]] = (rec.pop("values"), rec.pop("fps"))

    try:
        jobs = [({"input": str(path)}, (str(path),)) for path, _, _ in clips]
        with open(manifest_path, "w", encoding="utf-8") as log:
            _drive("index", clip_features, jobs, log, max_retries, result, bar, keep)
    finally:
        if owned:
            _import_ray().shutdown()
    bar.update(force=True)
    kept = [clip for clip in clips if str(clip[0]) in features]
    if not kept:
        raise BatchError(f"no clip could be read (see {manifest_path})")
    # The clips in the order `mocap search index` takes them.
    _mocap.search_build_index(
        kept, [features[str(clip[0])] for clip in kept], rule_name, os.fspath(output),
        trees=trees, candidates=candidates, min_entropy=min_entropy, frames=frames,
        seed=seed, bootstrap=bootstrap,
    )
    result.seconds = time.perf_counter() - start
    return result
