"""Takes/s of mocap.batch (clean with the shipped model, and index) with 1
and 2 local Ray workers against plain loops over the same Bandai takes: the
CLI per take, and mocap.clean in one Python process. Writes Markdown to
stdout (bench/batch/run.sh); progress to stderr."""

import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import ray

import mocap
import mocap.batch

folder, count, cli = Path(sys.argv[1]), sys.argv[2], sys.argv[3]
takes = sorted(folder.rglob("*.bvh"))
if count != "all":
    takes = takes[: int(count)]
assert takes, f"no .bvh takes in {folder}"
n = len(takes)
seconds = sum(len(m) * m.frame_time for m in map(mocap.read, takes))
work = Path(tempfile.mkdtemp(prefix="mbb"))
rows = []


def log(*args):
    print(*args, file=sys.stderr, flush=True)


def row(table, name, wall, note=""):
    table.append(f"| {name} | {wall:.1f} | {n / wall:.2f} | {seconds / wall:.1f} | {note} |")
    log(table[-1])


def task_seconds(manifest):
    return sum(rec["seconds"] for rec in mocap.batch.read_manifest(manifest).values())


# Ray's start and stop on this machine, paid once per run.
start = time.perf_counter()
ray.init(num_cpus=2, include_dashboard=False, logging_level="WARNING")
ray.shutdown()
ray_start = time.perf_counter() - start
log(f"ray start and stop: {ray_start:.1f} s")

# ---- clean
clean = []
(work / "cli").mkdir()
start = time.perf_counter()
for t in takes:
    subprocess.run([cli, "clean", "apply", "-q", "-o", str(work / "cli" / t.name), str(t)], check=True)
row(clean, "loop: `mocap clean apply` per take", time.perf_counter() - start)

start = time.perf_counter()
(work / "py").mkdir()
for t in takes:
    mocap.clean(mocap.read(t)).write(work / "py" / t.name)
py_wall = time.perf_counter() - start
row(clean, "loop: `mocap.clean` in one Python process", py_wall)

in_task = {}
walls = {}
for cpus in (1, 2):
    start = time.perf_counter()
    r = mocap.batch.clean(takes, work / f"ray{cpus}", num_cpus=cpus, progress=False)
    walls[cpus] = time.perf_counter() - start
    assert r.done == n, r.errors
    in_task[cpus] = task_seconds(r.manifest)
    row(clean, f"`mocap.batch.clean`, local Ray, {cpus} worker(s)", walls[cpus],
        f"{in_task[cpus] / n:.3f} s a take in its task")
    for t in takes:  # the same output as the plain loop, byte for byte
        out = work / f"ray{cpus}" / t.name  # a list of takes: outputs by name
        assert out.read_bytes() == (work / "py" / t.name).read_bytes(), out
    shutil.rmtree(work / f"ray{cpus}")

# ---- index: features per clip on Ray, one forest
index = []
labels = ["--labels-from-name", "bandai-content"]
start = time.perf_counter()
subprocess.run([cli, "search", "index", *map(str, takes), *labels, "-q", "-o", str(work / "cli.idx")],
               check=True)
row(index, "`mocap search index` (one process)", time.perf_counter() - start)
index_task = {}
for cpus in (1, 2):
    start = time.perf_counter()
    r = mocap.batch.index(takes, work / f"ray{cpus}.idx", labels_from_name="bandai-content",
                          num_cpus=cpus, progress=False)
    wall = time.perf_counter() - start
    assert r.done == n, r.errors
    same = (work / f"ray{cpus}.idx").read_bytes() == (work / "cli.idx").read_bytes()
    assert same, "the batch index differs from the command's"
    index_task[cpus] = task_seconds(r.manifest)
    row(index, f"`mocap.batch.index`, local Ray, {cpus} worker(s)", wall,
        f"{index_task[cpus] / n:.3f} s a clip in its task; the same file as the command")

head = "| run | wall s | takes/s | motion s per wall s | note |\n|---|---|---|---|---|"
print(f"{n} Bandai takes ({seconds / 60:.0f} min of motion) under `{folder}`, "
      f"{os.cpu_count()} cores, {platform.processor() or platform.machine()}, "
      f"Python {platform.python_version()}, Ray {ray.__version__}. Every Ray output is checked "
      "byte for byte against the plain loop's (clean) or the command's (index).\n")
print("## Clean (the shipped model)\n")
print(head)
print("\n".join(clean))
# Ray's cost per take: the 1-worker wall less the one-off start and the
# tasks' own time (scheduling, moving results, the manifest).
overhead = (walls[1] - ray_start - in_task[1]) / n
print(f"\nRay's start and stop cost {ray_start:.1f} s once per run. With 1 worker, the time outside "
      f"the tasks (scheduling, moving results, the manifest) is {overhead * 1000:.0f} ms a take: the "
      f"wall less the start and the tasks' own time. A take spends {in_task[1] / n * 1000:.0f} ms in "
      f"its task against {py_wall / n * 1000:.0f} ms in the Python loop: a task runs mocap on one "
      "thread (RAYON_NUM_THREADS=1, one CPU reserved), the loop on every core.")
print("\n## Index (`--labels-from-name bandai-content`, 100 trees)\n")
print(head)
print("\n".join(index))

# The projection, from the measured time a take spends in its task with 2
# workers (both cores busy; Ray's start left out: it is paid once per run).
per_core = seconds / in_task[2]  # seconds of motion cleaned per core-second
core_hours = 1000 * 3600 / per_core / 3600
print("\n## Projection for 1,000 hours of capture (on paper, from the rows above)\n")
print(f"With 2 workers a take spent {in_task[2] / n:.3f} s in its task: {per_core:.1f} s of motion "
      f"cleaned per core-second, so 1,000 hours of capture need about {core_hours:.0f} core-hours: "
      + ", ".join(f"{core_hours / (16 * k):.1f} h on {k} node{'s' if k > 1 else ''} of 16 cores"
                  for k in (1, 8, 32))
      + ", if the takes scale as independent tasks do and storage keeps up.")
index_core_hours = 1000 * 3600 / (seconds / index_task[2]) / 3600
print(f"Indexing: the clips' features took {index_task[2]:.1f} core-seconds in their tasks "
      f"for {seconds / 60:.0f} min of motion, so 1,000 hours need about {index_core_hours:.2f} "
      "core-hours on the cluster: the storage that serves the files is likely to set the pace, not the "
      "cores. The forest "
      "is trained once, on the driver, on every clip: its time grows with the number of clips "
      "whatever the nodes, and was not measured beyond these.")
shutil.rmtree(work, ignore_errors=True)
