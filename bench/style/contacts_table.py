"""Table of `run.sh --contacts` (bench/style/out/contacts-table.md): elastic and
fixed patches with each root, without and with the foot-contact cleanup, side by
side (shipped fold, judge seed 1).

Usage: python3 bench/style/contacts_table.py bench/style/out RUNS_DIR > bench/style/out/contacts-table.md
bench/style/out holds run.sh's eval.json; RUNS_DIR holds eval-root-source.json and
the --contacts runs' eval-contacts-default-root.json, eval-contacts.json,
eval-root-from-feet.json and eval-root-from-feet-contacts.json.
"""
import json
import pathlib
import sys

from reports import method_row

out = pathlib.Path(sys.argv[1])
runs = pathlib.Path(sys.argv[2])
# (file, root, cleanup) in the order of the table.
RUNS = [
    ("eval.json", "default", False),
    ("eval-contacts-default-root.json", "default", True),
    ("eval-root-source.json", "source's path", False),
    ("eval-contacts.json", "source's path", True),
    ("eval-root-from-feet.json", "feet", False),
    ("eval-root-from-feet-contacts.json", "feet", True),
]
METHODS = ["elastic-patches", "fixed-patches"]

print(
    "| set | root | method | style acc. | where known | content acc. | planted foot sliding "
    "| foot skating | feet beyond real reach | jitter | distance ratio |"
)
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
reports = {
    name: json.loads(((out if name == "eval.json" else runs) / name).read_text())
    for name, _, _ in RUNS
}
for data_set in ["dataset-1", "dataset-2"]:
    for name, root, cleanup in RUNS:
        for method in METHODS:
            r = method_row(reports[name], data_set, method)
            label = method + (" + cleanup" if cleanup else "")
            print(
                f"| {data_set} | {root} | {label} | {100 * r['style_accuracy']:.1f}% "
                f"| {100 * r['style_accuracy_recognised']:.1f}% | {100 * r['content_accuracy']:.1f}% "
                f"| {r['planted_foot_sliding']:.2f} | {r['foot_skating']:.2f} | {r['beyond_real_reach']} "
                f"| {r['jitter']:.4f} | {r['distance_ratio']:.2f} |"
            )
