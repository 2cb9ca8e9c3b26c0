"""Table of bench/style/patch_judges.sh: the methods it ran (elastic patches by
default) at each patch length, judged by the three style judges with seeds 1-3,
both folds pooled.

Usage: python3 bench/style/patch_judges_table.py RUNS_DIR > bench/style/out/patch-judges.md
RUNS_DIR holds eval-p{P}-{forest,conv-net,both}-{last,first}-seed{N}.json.
"""
import json
import pathlib
import re
import sys

from reports import method_row, pooled

root = pathlib.Path(sys.argv[1])
JUDGES = [j for j in ["forest", "conv-net", "both"] if any(root.glob(f"eval-p*-{j}-*.json"))]
FOLDS = ["last", "first"]
SEEDS = [1, 2, 3]
SETS = ["dataset-1", "dataset-2"]
PATCHES = sorted({int(re.match(r"eval-p(\d+)-", p.name).group(1)) for p in root.glob("eval-p*.json")})
# The methods in the reports, in the order `mocap style eval` writes them.
METHODS = [m["method"] for m in json.loads(next(root.glob("eval-p*.json")).read_text())["sets"][0]["methods"]]


def rows(p, judge, seed, data_set, method):
    return [
        method_row(
            json.loads((root / f"eval-p{p}-{judge}-{fold}-seed{seed}.json").read_text()),
            data_set,
            method,
        )
        for fold in FOLDS
    ]


print("## Each method at each patch length, every judge and seed, both folds pooled\n")
print("| set | method | P | judge | seed 1 | seed 2 | seed 3 | mean style | mean content | pairs |")
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
for data_set in SETS:
    for method in METHODS:
        for judge in JUDGES:
            for p in PATCHES:
                style = [pooled(rows(p, judge, s, data_set, method), "style_accuracy") for s in SEEDS]
                content = [pooled(rows(p, judge, s, data_set, method), "content_accuracy") for s in SEEDS]
                pairs = sum(r["pairs"] for r in rows(p, judge, 1, data_set, method))
                cells = " | ".join(f"{100 * v:.1f}%" for v in style)
                print(
                    f"| {data_set} | {method} | {p} | {judge} | {cells} | {100 * sum(style) / 3:.1f}% "
                    f"| {100 * sum(content) / 3:.1f}% | {pairs} |"
                )
