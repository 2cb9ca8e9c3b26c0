#!/usr/bin/env python3
"""Peak memory and wall time of every `mocap` command that reads a take,
against the size of the take. Run through bench/memory.sh.

Long takes are made by repeating the frame lines of a real Bandai take (the
header's `Frames:` set to match), to about each of the sizes asked for. Each
command runs under `/usr/bin/time -v` (peak resident memory, wall time); a
watcher stops a run whose resident memory passes the limit, or that runs past
the time limit, and the row says so.

Rows go to bench/results/memory-rows/LABEL.tsv (one file per binary: the
build before a change and after it); bench/results/memory.md is assembled
from every rows file.
"""

import argparse
import glob
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from datetime import date

MB = 1_000_000


def make_take(source, path, size_mb):
    """`source` with its frame lines repeated to about `size_mb` MB."""
    with open(source, "rb") as f:
        lines = f.read().splitlines(keepends=True)
    at = next(i for i, l in enumerate(lines) if l.strip().lower().startswith(b"frame time"))
    header, frames = lines[:at + 1], [l for l in lines[at + 1:] if l.strip()]
    block = b"".join(frames)
    repeats = max(1, round(size_mb * MB / len(block)))
    with open(path, "wb") as out:
        for line in header:
            if line.strip().lower().startswith(b"frames"):
                line = b"Frames:\t%d\n" % (len(frames) * repeats)
            out.write(line)
        for _ in range(repeats):
            out.write(block)
    return len(frames) * repeats


def children(pid):
    """Every descendant of `pid`."""
    out = []
    try:
        for task in os.listdir(f"/proc/{pid}/task"):
            with open(f"/proc/{pid}/task/{task}/children") as f:
                for c in f.read().split():
                    out.append(int(c))
                    out.extend(children(int(c)))
    except OSError:
        pass
    return out


def rss_kb(pid):
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
    except OSError:
        pass
    return 0


def run(command, limit_kb, limit_s, log):
    """Runs `command` under /usr/bin/time -v with a watcher: (peak KiB,
    seconds, stopped reason or None, exit status)."""
    stats = log + ".time"
    start = time.monotonic()
    with open(log, "wb") as out:
        p = subprocess.Popen(["/usr/bin/time", "-v", "-o", stats] + command,
                             stdout=out, stderr=subprocess.STDOUT, process_group=0)
    stopped, watched_peak = None, 0
    while p.poll() is None:
        rss = sum(rss_kb(c) for c in children(p.pid))
        watched_peak = max(watched_peak, rss)
        if rss > limit_kb:
            stopped = "memory"
        elif time.monotonic() - start > limit_s:
            stopped = "time"
        if stopped:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait()
            break
        time.sleep(0.05)
    seconds = time.monotonic() - start
    peak = watched_peak
    try:
        text = open(stats).read()
        peak = max(peak, int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", text).group(1)))
        m = re.search(r"Elapsed \(wall clock\) time.*: (?:(\d+):)?(\d+):([\d.]+)", text)
        seconds = int(m.group(1) or 0) * 3600 + int(m.group(2)) * 60 + float(m.group(3))
    except (OSError, AttributeError):
        pass
    return peak, seconds, stopped, p.returncode


def commands(mocap, take, work, data):
    """(name, argv) of every command that reads the take."""
    out = os.path.join(work, "out")
    walk = os.path.join(data, "dataset-1_walk_normal_001.bvh")
    proud = os.path.join(data, "dataset-1_walk_proud_001.bvh")
    index = os.path.join(work, "library.json")
    q = [mocap, "--quiet"]
    return [
        ("info", q + ["info", take]),
        ("convert bvh->bvh", q + ["convert", take, out + ".bvh"]),
        ("convert --frames 0..1000 (cut)", q + ["convert", take, "--frames", "0..1000", out + ".bvh"]),
        ("convert --fps 60", q + ["convert", take, "--fps", "60", out + ".bvh"]),
        ("positions (CSV)", q + ["positions", take, "-o", out + ".csv"]),
        ("clean apply (shipped model)", q + ["clean", "apply", take, "-o", out + ".bvh"]),
        ("clean apply --filter butterworth:2:6", q + ["clean", "apply", take, "--filter", "butterworth:2:6", "-o", out + ".bvh"]),
        ("clean apply --filter butterworth-gcv:2", q + ["clean", "apply", take, "--filter", "butterworth-gcv:2", "-o", out + ".bvh"]),
        ("clean apply --despike (shipped model)", q + ["clean", "apply", take, "--despike", "-o", out + ".bvh"]),
        ("style apply", q + ["style", "apply", take, "--style", proud, "-o", out + ".bvh"]),
        ("search query (take as the query)", q + ["search", "query", take, "--index", index]),
        ("search find (walk in the take)", q + ["search", "find", walk, "--in", take, "--index", index]),
        ("render (PNG filmstrip)", q + ["render", take, "-o", out + ".png"]),
    ]


def same_outputs(other, argv, work, log):
    """Runs `argv` with the binary `other`, writing `ref.*` for `out.*`, and
    compares what both wrote (files and standard output): `yes`, or what
    differs."""
    out, ref = os.path.join(work, "out"), os.path.join(work, "ref")
    ref_log = log + ".ref"
    with open(ref_log, "wb") as f:
        subprocess.run([other] + [a.replace(out, ref) for a in argv[1:]],
                       stdout=f, stderr=subprocess.STDOUT)
    differs = []
    if open(log, "rb").read() != open(ref_log, "rb").read():
        differs.append("output text")
    for path in sorted(glob.glob(out + ".*")):
        twin = ref + path[len(out):]
        if not os.path.exists(twin) or subprocess.run(["cmp", "-s", path, twin]).returncode:
            differs.append(os.path.basename(path))
    return "yes" if not differs else "no: " + ", ".join(differs)


def human_kb(kb):
    return f"{kb / 1e6:.2f} GB" if kb >= 1e6 else f"{kb / 1e3:.0f} MB"


def human_s(s):
    return f"{s / 60:.1f} min" if s >= 600 else f"{s:.1f} s"


def main():
    a = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    a.add_argument("--mocap", required=True, help="the mocap binary to measure")
    a.add_argument("--label", default="current", help="rows file name (before, after...)")
    a.add_argument("--sizes", default="10,100,1000", help="take sizes in MB")
    a.add_argument("--only", default="", help="run only commands whose name contains this")
    a.add_argument("--limit-gb", type=float, default=8.0)
    a.add_argument("--limit-s", type=float, default=1200.0)
    a.add_argument("--data", default=os.environ.get("MOCAP_SHARED_DATA", "../shared/data") + "/bandai/dataset-1")
    a.add_argument("--work", default="target/memory-bench")
    a.add_argument("--results", default="bench/results")
    a.add_argument("--same-as", default="", help="another mocap binary whose outputs must be the same bytes")
    a.add_argument("--compare-up-to", type=int, default=100, help="compare outputs on takes up to this many MB")
    o = a.parse_args()
    os.makedirs(o.work, exist_ok=True)
    rows_dir = os.path.join(o.results, "memory-rows")
    os.makedirs(rows_dir, exist_ok=True)
    rows_path = os.path.join(rows_dir, o.label + ".tsv")
    rows = {}
    if os.path.exists(rows_path):  # keep rows of sizes or commands not rerun
        for line in open(rows_path).read().splitlines()[1:]:
            f = line.split("\t")
            rows[(f[0], f[1])] = f
    source = os.path.join(o.data, "dataset-1_walk_normal_001.bvh")
    # A small library for the search commands: four contents.
    index = os.path.join(o.work, "library.json")
    if not os.path.exists(index):
        clips = sorted(c for content in ["bow", "dash", "run", "walk"]
                       for c in glob.glob(os.path.join(o.data, f"dataset-1_{content}_*.bvh")))
        subprocess.run([o.mocap, "--quiet", "search", "index", *clips, "--labels-from-name",
                        "bandai-content", "-o", index], check=True)
    for size in [int(s) for s in o.sizes.split(",")]:
        take = os.path.join(o.work, f"take-{size}MB.bvh")
        frames = make_take(source, take, size)
        mb = os.path.getsize(take) / MB
        for name, argv in commands(o.mocap, take, o.work, o.data):
            if o.only and o.only not in name:
                continue
            log = os.path.join(o.work, f"{size}MB-{re.sub(r'[^a-z0-9]+', '-', name)}.log")
            peak, seconds, stopped, status = run(argv, o.limit_gb * 1e6, o.limit_s, log)
            if stopped == "memory":
                result = f"> {o.limit_gb:g} GB (stopped)"
            elif stopped == "time":
                result = f"{human_kb(peak)} at {o.limit_s:g} s (stopped)"
            else:
                result = human_kb(peak)
            error = ""
            if not stopped and status != 0:
                last = [l for l in open(log, errors="replace").read().splitlines() if l.strip()]
                error = (last[-1] if last else f"exit {status}")[:600]
            same = ""
            if o.same_as and size <= o.compare_up_to and not stopped:
                same = same_outputs(o.same_as, argv, o.work, log)
            row = [name, f"{size}", f"{mb:.0f}", f"{frames}", result, human_s(seconds), error, same]
            rows[(name, f"{size}")] = row
            print("\t".join(row), flush=True)
            for f in glob.glob(os.path.join(o.work, "out.*")) + glob.glob(os.path.join(o.work, "ref.*")):
                os.remove(f)
        os.remove(take)
        with open(rows_path, "w") as f:
            f.write("command\tsize_mb\tfile_mb\tframes\tpeak_rss\twall\terror\tsame_as_other\n")
            for row in rows.values():
                f.write("\t".join(row) + "\n")
    write_page(o.results, rows_dir)


def write_page(results, rows_dir):
    """bench/results/memory.md from the rows files: peak memory and wall
    time per command and take size, `before -> after` where both exist."""
    labels = sorted(p[:-4] for p in os.listdir(rows_dir) if p.endswith(".tsv"))
    by = {}
    for label in labels:
        for line in open(os.path.join(rows_dir, label + ".tsv")).read().splitlines()[1:]:
            r = line.split("\t")
            by[(label, r[0], int(r[1]))] = r
    shown = [l for l in ["before", "after"] if l in labels] or labels
    rows = [r for (l, _, _), r in by.items() if l in shown]
    sizes = sorted({int(r[1]) for r in rows})
    order = [n for n, _ in commands("mocap", "take", "work", "data")]
    names = sorted(dict.fromkeys(r[0] for r in rows),
                   key=lambda n: order.index(n) if n in order else len(order))
    frames = {int(r[1]): (r[2], int(r[3])) for r in rows}
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
    text = [
        "# Memory against the length of a take",
        "",
        "```sh",
        "bench/memory.sh before OLD/mocap                      # a build of commit ea6ed62, before the memory work",
        "bench/memory.sh after target/release/mocap OLD/mocap  # the current build, outputs compared with OLD's",
        "```",
        "",
        "Peak resident memory and wall time of every command that reads a take, under `/usr/bin/time -v`,",
        "on takes made by repeating the frame lines of the Bandai take `dataset-1_walk_normal_001.bvh`",
        "(22 joints, 132 channels, 30 fps) to about 10 MB, 100 MB and 1 GB of BVH text. A run is stopped past",
        f"8 GB or 20 minutes. {cpu}, {os.cpu_count()} cores shared with other builds (times are noisy), {date.today()}.",
        "Cells: " + " -> ".join(shown) + ".",
        "",
    ]
    compared = [r for (l, _, _), r in by.items() if l == shown[-1] and len(r) > 7 and r[7]]
    if compared:
        differ = [f"{r[0]} ({r[1]} MB): {r[7]}" for r in compared if r[7] != "yes"]
        takes = " and ".join(f"{s} MB" for s in sorted({int(r[1]) for r in compared}))
        text += ([f"Outputs: the {len(compared)} runs on the {takes} takes were repeated with the other build",
                  "(`--same-as`): every file and every printed line the same bytes.", ""]
                 if not differ else ["Outputs that differ from the other build's:", ""]
                 + [f"- {d}" for d in differ] + [""])
    notes = []

    def cell(name, size, what):
        parts = []
        for label in shown:
            r = by.get((label, name, size))
            if r is None:
                parts.append("-")
                continue
            value = r[4] if what == "memory" else r[5]
            if len(r) > 6 and r[6]:
                note = re.sub(r"\S*/(take-\d+MB\.bvh)", r"\1", r[6])
                if note not in notes:
                    notes.append(note)
                value += f" (refused [{notes.index(note) + 1}])"
            parts.append(value)
        return " -> ".join(parts)

    for what, title in [("memory", "Peak memory"), ("time", "Wall time")]:
        text.append(f"## {title}")
        text.append("")
        text.append("| command | " + " | ".join(
            f"{frames[s][0]} MB ({frames[s][1]:,} frames)" for s in sizes) + " |")
        text.append("| --- |" + " ---: |" * len(sizes))
        for n in names:
            text.append(f"| {n} | " + " | ".join(cell(n, s, what) for s in sizes) + " |")
        text.append("")
    text += [
        "What the current build holds, besides a fixed part (the models, for clean and style): the",
        "take's channel values (4 bytes each) for `info`, `convert` and",
        "`positions` (their poses are computed 1024 frames at a time); the take and its cleaned copy for the",
        "filters, and the Wiener filter's output besides for the shipped model (the filter runs 512 segments",
        "at a time, the network's windows are blended batch by batch), and the bridged copy with `--despike`;",
        "`search` and `render` the take's global poses too. `convert --fps 60` writes twice the frames.",
        "`style apply` refuses sources over an hour (its message gives the memory it would need).",
        "",
    ]
    if notes:
        text.append("Refused, with the message:")
        text.append("")
        text.extend(f"{k + 1}. {n}" for k, n in enumerate(notes))
        text.append("")
    with open(os.path.join(results, "memory.md"), "w") as f:
        f.write("\n".join(text))


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--page":
        write_page("bench/results", "bench/results/memory-rows")
    else:
        main()
