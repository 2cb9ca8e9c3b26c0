"""Tables of bench/style/judges.sh: the three style judges on real clips
and on outputs, three judge seeds, both folds.

Usage: python3 bench/style/judges_table.py RUNS_DIR > bench/style/out/judges.md
RUNS_DIR holds classifiers-{forest,conv-net,both}-{last,first}-seedN.json and
eval-{forest,conv-net,both}-{last,first}-seedN.json.
"""
import json
import pathlib
import sys

from reports import method_row, pooled

root = pathlib.Path(sys.argv[1])
JUDGES = ["forest", "conv-net", "both"]
FOLDS = ["last", "first"]
SEEDS = [1, 2, 3]
METHODS = ["elastic-patches", "fixed-patches", "whitening-colouring", "adain"]


def load(kind, judge, fold, seed):
    return json.loads((root / f"{kind}-{judge}-{fold}-seed{seed}.json").read_text())


print("## The style judges on real dataset-1 clips\n")
print("Cross-validated: leaving one walking content out at a time (60 training clips);")
print("held out: the 15 held-out walks, which are the evaluation's style clips.\n")
print("| judge | fold | cross-validated, seeds 1 / 2 / 3 | mean | held out, seeds 1 / 2 / 3 | mean |")
print("| --- | --- | --- | --- | --- | --- |")
for judge in JUDGES:
    for fold in FOLDS:
        checks = [
            next(c for c in load("classifiers", judge, fold, s) if c["set"] == "dataset-1")
            for s in SEEDS
        ]
        cv = [100 * c["cross_validated_style"] for c in checks]
        held = [100 * c["held_out_style"] for c in checks]
        print(
            f"| {judge} | {fold} | {' / '.join(f'{v:.1f}' for v in cv)} | {sum(cv) / 3:.1f} "
            f"| {' / '.join(f'{v:.1f}' for v in held)} | {sum(held) / 3:.1f} |"
        )

print("\n## Outputs judged by each, both folds pooled\n")
print("Style (and content) accuracy of the outputs over both folds' pairs, per judge seed;")
print("the content judge is the same forest in both rows of a seed.\n")
print("| set | method | judge | seed 1 | seed 2 | seed 3 | mean style | mean content |")
print("| --- | --- | --- | --- | --- | --- | --- | --- |")
for data_set in ["dataset-1", "dataset-2"]:
    for method in METHODS:
        for judge in JUDGES:
            rows = {
                seed: [method_row(load("eval", judge, fold, seed), data_set, method) for fold in FOLDS]
                for seed in SEEDS
            }
            every = [r for seed in SEEDS for r in rows[seed]]
            cells = [f"{100 * pooled(rows[seed], 'style_accuracy'):.1f}%" for seed in SEEDS]
            print(
                f"| {data_set} | {method} | {judge} | {' | '.join(cells)} "
                f"| {100 * pooled(every, 'style_accuracy'):.1f}% "
                f"| {100 * pooled(every, 'content_accuracy'):.1f}% |"
            )
