"""Summary tables of bench/cameras/run.sh's JSON reports (Markdown on stdout)."""
import json
import pathlib
import sys

out = pathlib.Path(sys.argv[1])
methods = ["plain", "scores", "bone-length", "range-of-motion", "robust"]


def cell(v, digits=1):
    return "-" if v is None else f"{v:.{digits}f}"


print("## Real capture: Pose2Sim demo, against Pose2Sim's own triangulation\n")
print("| trial | keypoints from | method | reprojection, every view (px) | bone-length spread (mm) | to Pose2Sim (mm) |")
print("| --- | --- | --- | ---: | ---: | ---: |")
for f in sorted(out.glob("pose2sim-*-pose*.json")):
    r = json.loads(f.read_text())
    trial = pathlib.Path(r["trial"])
    for m in r["methods"]:
        if m["method"] in ("plain", "robust"):
            print(f"| {trial.parent.name} | {trial.name} | {m['method']} | {cell(m['reprojection_all_px'], 2)} | "
                  f"{cell(m['bone_spread_mm'])} | {cell(m['to_reference_mm'])} |")
    ref = r.get("reference")
    if ref:
        print(f"| {trial.parent.name} | {trial.name} | Pose2Sim | {cell(ref['reprojection_all_px'], 2)} | "
              f"{cell(ref['bone_spread_mm'])} | - |")

multi = {(p, t): json.loads((out / f"multi-person{p}-{t}.json").read_text())
         for p in (1, 2) for t in ("P1", "P2") if (out / f"multi-person{p}-{t}.json").exists()}
if len(multi) == 4:
    robust = lambda r: next(m for m in r["methods"] if m["method"] == "robust")
    d = {k: robust(r)["to_reference_mm"] for k, r in multi.items()}
    pairs = min([(("P1", "P2"), d[1, "P1"] + d[2, "P2"]), (("P2", "P1"), d[1, "P2"] + d[2, "P1"])],
                key=lambda x: x[1])[0]
    print("\n## Two people, raw OpenPose output (S00_P01_T02_Participants1-2/pose)\n")
    print("Each person mocap finds (robust method), against the Pose2Sim person nearest it and the other.\n")
    print("| person | matches Pose2Sim's | distance to it (mm) | to the other (mm) | reprojection, every view (px) | bone-length spread (mm) | Pose2Sim's spread (mm) |")
    print("| --- | --- | ---: | ---: | ---: | ---: | ---: |")
    for p, theirs in zip((1, 2), pairs):
        other = "P2" if theirs == "P1" else "P1"
        r = multi[p, theirs]
        m = robust(r)
        print(f"| {p} | {theirs} | {cell(m['to_reference_mm'])} | {cell(robust(multi[p, other])['to_reference_mm'])} | "
              f"{cell(m['reprojection_all_px'], 2)} | {cell(m['bone_spread_mm'])} | {cell(r['reference']['bone_spread_mm'])} |")

sims = sorted(out.glob("sim-*.json"))
if sims:
    print("\n## Simulated cameras on Bandai takes, against the truth\n")
    print("MPJPE (mm) over the keypoints each method triangulated; coverage in brackets.\n")
    print("| take | frames | " + " | ".join(methods) + " | best / plain |")
    print("| --- | ---: | " + " | ".join("---:" for _ in methods) + " | ---: |")
    sums = {m: [] for m in methods}
    ratios = []
    for f in sims:
        r = json.loads(f.read_text())
        by = {m["method"]: m for m in r["methods"]}
        row = []
        for m in methods:
            v = by[m]["mpjpe_mm"]
            sums[m].append(v)
            row.append(f"{cell(v)} ({100 * by[m]['coverage']:.0f}%)")
        ratios.append(r["best_over_plain"])
        print(f"| {f.stem[4:]} | {r['frames']} | " + " | ".join(row) + f" | {cell(r['best_over_plain'], 2)} |")
    mean = lambda xs: sum(xs) / len(xs) if xs and None not in xs else None
    print("| **mean** | | " + " | ".join(cell(mean(sums[m])) for m in methods)
          + f" | {cell(mean(ratios), 2)} |")
    fps = [m["frames_per_second"] for f in sims for m in json.loads(f.read_text())["methods"] if m["method"] == "robust"]
    print(f"\nRobust method, 4 cameras x 25 keypoints: {min(fps):.0f}-{max(fps):.0f} frames/s on one core "
          "(a whole trial's second pass, release build).")
