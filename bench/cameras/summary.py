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

sims = sorted(out.glob("sim-*.json"))
if sims:
    print("\n## Simulated cameras on Bandai takes, against the truth\n")
    print("MPJPE (mm) over the keypoints each method triangulated; coverage in brackets.\n")
    print("| take | " + " | ".join(methods) + " | best / plain |")
    print("| --- | " + " | ".join("---:" for _ in methods) + " | ---: |")
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
        print(f"| {f.stem[4:]} | " + " | ".join(row) + f" | {cell(r['best_over_plain'], 2)} |")
    mean = lambda xs: sum(xs) / len(xs) if xs and None not in xs else None
    print("| **mean** | " + " | ".join(cell(mean(sums[m])) for m in methods)
          + f" | {cell(mean(ratios), 2)} |")
    fps = [m["frames_per_second"] for f in sims for m in json.loads(f.read_text())["methods"] if m["method"] == "robust"]
    print(f"\nRobust method, 4 cameras x 25 keypoints: {min(fps):.0f}-{max(fps):.0f} frames/s on one core "
          "(whole-trial pass, debug-free release build).")
