"""Table of bench/style/asymmetry.sh: every method on both folds, with the
source's left-right asymmetry kept along the take (the default, eval.json),
kept as one offset per clip (`--asymmetry source-clip`) and not kept
(`--asymmetry style`, the report's method).

Usage: python3 bench/style/asymmetry_table.py RUNS_DIR   (the first part of bench/style/out/asymmetry.md)
RUNS_DIR holds eval-{style,source-clip}-{last,first}.json.
"""
import pathlib
import sys

from reports import method_row, pooled

OUT = pathlib.Path(__file__).resolve().parent / "out"
RUNS_DIR = pathlib.Path(sys.argv[1])
RUNS = {
    "style (report)": (RUNS_DIR / "eval-style-last.json", RUNS_DIR / "eval-style-first.json"),
    "source-clip": (
        RUNS_DIR / "eval-source-clip-last.json",
        RUNS_DIR / "eval-source-clip-first.json",
    ),
    "source (default)": (OUT / "eval.json", OUT / "fold-first/eval.json"),
}
METHODS = ["elastic-patches", "fixed-patches", "whitening-colouring", "adain"]


print("Style and content accuracy (judge seed 1) on the shipped fold (last take held out) /")
print("the other fold (first take held out) / both pooled; |T_out - T_style|, foot skating")
print("and jitter pooled over both folds.\n")
print("| set | method | asymmetry | style acc. | content acc. | \\|T_out - T_style\\| (s) | foot skating | jitter |")
print("| --- | --- | --- | --- | --- | --- | --- | --- |")
for data_set in ["dataset-1", "dataset-2"]:
    for method in METHODS:
        for asymmetry, paths in RUNS.items():
            rows = [method_row(p, data_set, method) for p in paths]

            def folds(key):
                cells = [f"{100 * r[key]:.1f}" for r in rows] + [f"{100 * pooled(rows, key):.1f}%"]
                return " / ".join(cells)

            print(
                f"| {data_set} | {method} | {asymmetry} | {folds('style_accuracy')} "
                f"| {folds('content_accuracy')} | {pooled(rows, 'period_error_to_style'):.3f} "
                f"| {pooled(rows, 'foot_skating'):.1f} | {pooled(rows, 'jitter'):.3f} |"
            )
