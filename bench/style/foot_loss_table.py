"""Summary table of bench/style/foot_loss.sh: one row per model.

Reads, in the folder given, feet-NAME.md (example foot_cleanup) and
eval-NAME.json (style_eval), and train-NAME.json where there is one (in
session 18 the weight-0 models were run.sh's; their reports were copied
there in session 19, when foot_loss.sh began to train them too).
"""
import json
import sys
from pathlib import Path

from reports import method_row

MODELS = [
    ("s1-w0", "seed 1, weight 0 (shipped until session 18)", None),
    ("s1-w300", "seed 1, weight 300", None),
    ("s1-w1000", "seed 1, weight 1000", None),
    ("s2-w0", "seed 2, weight 0", None),
    ("s2-w300", "seed 2, weight 300", None),
    ("first-w0", "other fold, weight 0", None),
    ("first-w300", "other fold, weight 300", None),
]


def feet_rows(path):
    """{(set, row name): [columns]} of a foot_cleanup table."""
    rows = {}
    for line in path.read_text().splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 8 and cells[0].startswith("dataset"):
            rows[(cells[0], cells[1])] = cells[2:]
    return rows


def main(folder):
    folder = Path(folder)
    print(
        "| model | validation MSE | set | flat-foot sliding, sources through the autoencoder (cm/s) "
        "| flat-foot sliding, outputs (cm/s) | jitter, outputs | style acc. | content acc. "
        "| \\|T_out - T_style\\| (s) |"
    )
    print("| --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    for name, label, train_file in MODELS:
        feet_path, eval_path = folder / f"feet-{name}.md", folder / f"eval-{name}.json"
        if not (feet_path.exists() and eval_path.exists()):
            continue
        train_path = Path(train_file) if train_file else folder / f"train-{name}.json"
        history = json.loads(train_path.read_text())["history"]["epochs"]
        mse = f"{history[-1]['valid_loss']:.4f}"
        feet = feet_rows(feet_path)
        report = json.loads(eval_path.read_text())
        for s in report["sets"]:
            row = method_row(report, s["set"], "elastic-patches")
            recon = feet[(s["set"], "sources through the autoencoder (strength 0)")]
            print(
                f"| {label} | {mse} | {s['set']} | {float(recon[2]):.2f} "
                f"| {row['planted_foot_sliding']:.2f} | {row['jitter']:.4f} "
                f"| {100 * row['style_accuracy']:.1f}% | {100 * row['content_accuracy']:.1f}% "
                f"| {row['period_error_to_style']:.3f} |"
            )


if __name__ == "__main__":
    main(sys.argv[1])
