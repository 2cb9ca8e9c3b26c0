"""Takes/s of mocap.batch.clean (the shipped model) with 1 and 2 local Ray
workers against plain loops: `mocap clean apply` per take, and mocap.clean in
one Python process. Writes a Markdown table to stdout (bench/batch/run.sh)."""

import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import mocap
import mocap.batch

folder, count, cli = Path(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
takes = sorted(folder.glob("*.bvh"))[:count]
assert takes, f"no .bvh takes in {folder}"
seconds = sum(len(mocap.read(t)) * mocap.read(t).frame_time for t in takes)
work = Path(tempfile.mkdtemp(prefix="mbb"))
rows = []


def row(name, wall, note=""):
    rows.append(f"| {name} | {wall:.1f} | {len(takes) / wall:.2f} | {seconds / wall:.1f} | {note} |")
    print(rows[-1], file=sys.stderr, flush=True)


(work / "cli").mkdir()
start = time.perf_counter()
for t in takes:
    subprocess.run([cli, "clean", "apply", "-q", "-o", str(work / "cli" / t.name), str(t)], check=True)
row("loop: `mocap clean apply` per take", time.perf_counter() - start, f"`{cli}`")

start = time.perf_counter()
(work / "py").mkdir()
for t in takes:
    mocap.clean(mocap.read(t)).write(work / "py" / t.name)
row("loop: `mocap.clean` in one Python process", time.perf_counter() - start,
    f"the installed wheel ({Path(mocap.__file__).parent})")

rates = {}
for cpus in (1, 2):
    start = time.perf_counter()
    r = mocap.batch.clean(takes, work / f"ray{cpus}", num_cpus=cpus, progress=False)
    assert r.done == len(takes), r.errors
    task_s = sum(rec["seconds"] for rec in mocap.batch.read_manifest(r.manifest).values())
    rates[cpus] = task_s
    row(f"`mocap.batch.clean`, local Ray, {cpus} worker(s)", time.perf_counter() - start,
        f"wall includes starting Ray; {task_s / len(takes):.2f} s a take in its task")
    for t in takes:  # the same output as the plain loop
        assert (work / f"ray{cpus}" / t.name).read_bytes() == (work / "py" / t.name).read_bytes()

print(f"{len(takes)} Bandai takes ({seconds:.0f} s of motion) from `{folder}`, the shipped model, "
      f"{os.cpu_count()} cores, {platform.processor() or platform.machine()}, Python {platform.python_version()}.\n")
print("| run | wall s | takes/s | motion s per wall s | note |\n|---|---|---|---|---|")
print("\n".join(rows))

# The projection, from the measured time a take spends in its task with 2
# workers (Ray's start-up left out: it is paid once per run).
per_core = seconds / rates[2]  # seconds of motion cleaned per core-second
core_hours = 1000 * 3600 / per_core / 3600
print(f"\n## Projection for 1,000 hours of capture (on paper, from the row above)\n")
print(f"With 2 workers a take spent {rates[2] / len(takes):.2f} s in its task: {per_core:.1f} s of motion "
      f"cleaned per core-second, so 1,000 hours of capture need about {core_hours:.0f} core-hours: "
      + ", ".join(f"{core_hours / (16 * n):.1f} h on {n} node{'s' if n > 1 else ''} of 16 cores"
                  for n in (1, 8, 32))
      + ", if the takes scale as independent tasks do and storage keeps up. "
      "Indexing is not in the batch layer yet.")
shutil.rmtree(work, ignore_errors=True)
