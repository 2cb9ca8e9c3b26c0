"""Mean and spread over training seeds of the style evaluation (made by bench/style/mirror_fix.sh).

Usage: python3 bench/style/seeds_table.py DIR  (DIR holds KIND-seedN/{eval,train}.json)
"""
import json
import pathlib
import statistics
import sys

root = pathlib.Path(sys.argv[1])
runs = {}
for path in sorted(root.glob("*-seed*/eval.json")):
    kind, seed = path.parent.name.rsplit("-seed", 1)
    runs.setdefault(kind, {})[int(seed)] = json.loads(path.read_text())

COLUMNS = [
    ("style acc.", "style_accuracy", 100, "{:.1f}%"),
    ("where known", "style_accuracy_recognised", 100, "{:.1f}%"),
    ("content acc.", "content_accuracy", 100, "{:.1f}%"),
    ("|T_out - T_style| (s)", "period_error_to_style", 1, "{:.3f}"),
    ("closer to style", "closer_to_style", 100, "{:.0f}%"),
    ("foot skating", "foot_skating", 1, "{:.1f}"),
    ("jitter", "jitter", 1, "{:.3f}"),
    ("validation loss", None, 1, "{:.3f}"),
]

print("| training data | seeds | set | method | " + " | ".join(c[0] for c in COLUMNS) + " |")
print("| --- | --- | --- | --- | " + " | ".join("---" for _ in COLUMNS) + " |")
for kind, by_seed in runs.items():
    seeds = sorted(by_seed)
    first = by_seed[seeds[0]]
    for s_index, s in enumerate(first["sets"]):
        for m_index, m in enumerate(s["methods"]):
            if m["method"] not in ("elastic-patches", "fixed-patches"):
                continue
            cells = []
            for title, key, scale, fmt in COLUMNS:
                if key is None:
                    values = []
                    for seed in seeds:
                        train = root / f"{kind}-seed{seed}" / "train.json"
                        epochs = json.loads(train.read_text())["history"]["epochs"]
                        values.append(epochs[-1]["valid_loss"])
                else:
                    values = [
                        by_seed[seed]["sets"][s_index]["methods"][m_index][key] * scale
                        for seed in seeds
                    ]
                mean = statistics.mean(values)
                spread = f" ({fmt.format(min(values))}-{fmt.format(max(values))})" if len(values) > 1 else ""
                cells.append(fmt.format(mean) + spread)
            print(f"| {kind} | {','.join(map(str, seeds))} | {s['set']} | {m['method']} | " + " | ".join(cells) + " |")
