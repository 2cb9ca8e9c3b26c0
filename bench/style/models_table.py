"""Two or more models' runs of bench/style/patch_judges.sh side by side:
elastic patches, every judge and seed found, per fold and both folds pooled.

Usage: python3 bench/style/models_table.py NAME=RUNS_DIR NAME=RUNS_DIR ... > table.md
Each RUNS_DIR holds eval-p{P}-{judge}-{last,first}-seed{N}.json of one model
pair (LAST_MODEL, FIRST_MODEL); a seed without a report for every fold of a
row is shown as "-" and left out of that row's means.
"""
import json
import pathlib
import sys

from reports import method_row, pooled

models = [arg.split("=", 1) for arg in sys.argv[1:]]
JUDGES = ["forest", "conv-net", "both"]
SEEDS = [1, 2, 3]
SETS = ["dataset-1", "dataset-2"]


def rows(root, judge, seed, data_set, folds):
    out = []
    for fold in folds:
        for path in pathlib.Path(root).glob(f"eval-p*-{judge}-{fold}-seed{seed}.json"):
            out.append(method_row(json.loads(path.read_text()), data_set, "elastic-patches"))
    return out


print("| set | judge | folds | model | seed 1 | seed 2 | seed 3 | mean style | mean content | sliding | jitter |")
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
for data_set in SETS:
    for judge in JUDGES:
        for folds in (["last"], ["first"], ["last", "first"]):
            for name, root in models:
                # Seeds whose runs exist for every fold asked; a missing seed is "-".
                per_seed = {s: rows(root, judge, s, data_set, folds) for s in SEEDS}
                per_seed = {s: r for s, r in per_seed.items() if len(r) == len(folds)}
                if not per_seed:
                    continue
                style = {s: pooled(r, "style_accuracy") for s, r in per_seed.items()}
                every = [x for r in per_seed.values() for x in r]
                cells = " | ".join(f"{100 * style[s]:.1f}%" if s in style else "-" for s in SEEDS)
                mean = sum(style.values()) / len(style)
                print(
                    f"| {data_set} | {judge} | {' + '.join(folds)} | {name} | {cells} "
                    f"| {100 * mean:.1f}% | {100 * pooled(every, 'content_accuracy'):.1f}% "
                    f"| {pooled(every, 'planted_foot_sliding'):.2f} | {pooled(every, 'jitter'):.3f} |"
                )
