"""Tables of bench/style/patch_select.sh: the patch length P chosen on one
fold's pairs and judged on the other fold's.

Usage: python3 bench/style/patch_select.py RUNS_DIR > bench/style/out/patch-select.md
RUNS_DIR holds eval-p{P}-{last,first}.json (`mocap style eval --json` reports,
judge seed 1).

The rule, fixed before the runs: on the choosing fold, the P with the highest
style accuracy of elastic patches, averaged over dataset-1 and dataset-2,
among the P whose content accuracy is at least 90% on both sets (the issue's
content target); ties go to the P closest to the reference length 32. The
rule was fixed for the grid 24-56; 64 and 72 look past its edge.
"""
import json
import pathlib
import re
import sys

from reports import method_row, pooled

root = pathlib.Path(sys.argv[1])
FOLDS = ["last", "first"]
SETS = ["dataset-1", "dataset-2"]
# The length each choice is compared with.
REFERENCE = 32
runs = {}
for path in root.glob("eval-p*-*.json"):
    p, fold = re.fullmatch(r"eval-p(\d+)-(\w+)\.json", path.name).groups()
    runs[(int(p), fold)] = json.loads(path.read_text())
PATCHES = sorted({p for p, _ in runs})


def row(p, fold, data_set, method="elastic-patches"):
    return method_row(runs[(p, fold)], data_set, method)


def score(p, fold):
    """The choosing rule's figure, or None where content misses 90%."""
    if any(row(p, fold, s)["content_accuracy"] < 0.9 for s in SETS):
        return None
    return sum(row(p, fold, s)["style_accuracy"] for s in SETS) / len(SETS)


def cells(rows):
    return (
        f"{100 * pooled(rows, 'style_accuracy'):.1f}% | {100 * pooled(rows, 'content_accuracy'):.1f}% "
        f"| {pooled(rows, 'period_error_to_style'):.3f} | {pooled(rows, 'planted_foot_sliding'):.1f} "
        f"| {pooled(rows, 'jitter'):.3f} | {sum(r['pairs'] for r in rows)}"
    )


HEADER = (
    "| style acc. | content acc. | \\|T_out - T_style\\| (s) | planted foot sliding (cm/s) "
    "| jitter | pairs |"
)
RULE = "| --- " * 10 + "|"

print("## Every patch length on each fold (judge seed 1)\n")
print(f"| P | fold | set | method {HEADER}")
print(RULE)
for p in PATCHES:
    for fold in FOLDS:
        for s in SETS:
            for method in ["elastic-patches", "fixed-patches"]:
                print(f"| {p} | {fold} | {s} | {method} | {cells([row(p, fold, s, method)])} |")

print("\n## P chosen on one fold, judged on the other\n")
print("The choosing figure: elastic patches' style accuracy averaged over the two sets,")
print("where content accuracy is at least 90% on both (`-` where it is not).\n")
print("| P | " + " | ".join(f"fold {f}" for f in FOLDS) + " |")
print("| --- " * (len(FOLDS) + 1) + "|")
for p in PATCHES:
    figures = [score(p, f) for f in FOLDS]
    print(f"| {p} | " + " | ".join("-" if v is None else f"{100 * v:.1f}%" for v in figures) + " |")


def choose_and_judge(candidates, title):
    """Each fold judged with the P the other fold chooses among `candidates`."""
    print(f"\n### {title}\n")
    print(f"| chosen on | P | judged on | set {HEADER}")
    print(RULE)
    chosen = {}
    for choose, judge in [("last", "first"), ("first", "last")]:
        valid = [p for p in candidates if score(p, choose) is not None]
        best = max(valid, key=lambda p: (score(p, choose), -abs(p - REFERENCE)))
        chosen[judge] = best
        for s in SETS:
            print(f"| {choose} | {best} | {judge} | {s} | {cells([row(best, judge, s)])} |")
            print(f"| (reference) | {REFERENCE} | {judge} | {s} | {cells([row(REFERENCE, judge, s)])} |")
    print("\nBoth folds pooled: each fold judged with the P chosen on the other, against the reference length.\n")
    print(f"| P | set {HEADER}")
    print("| --- " * 8 + "|")
    for s in SETS:
        print(f"| chosen on the other fold | {s} | {cells([row(chosen[f], f, s) for f in FOLDS])} |")
        print(f"| {REFERENCE} | {s} | {cells([row(REFERENCE, f, s) for f in FOLDS])} |")


def keeps_every_pair(p):
    return all(
        row(p, f, s)["pairs"] == row(REFERENCE, f, s)["pairs"] for f in FOLDS for s in SETS
    )


choose_and_judge(PATCHES, "The rule as fixed before the runs")
kept = [p for p in PATCHES if keeps_every_pair(p)]
choose_and_judge(
    kept,
    "Only lengths that keep every pair ("
    f"{', '.join(str(p) for p in PATCHES if p not in kept) or 'none'} "
    "refuse clips shorter than two patches, and some pairs drop out)",
)
