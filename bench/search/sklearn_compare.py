"""scikit-learn's RandomForestClassifier on the feature matrix that
`cargo run --release -p mocap-search --example bench -- --features-csv FILE ...`
writes: one clip a line, `label,train|test,feature...` (the interval means).

Same settings as mocap-search's forest: 100 trees, entropy criterion,
64 candidate features per node, bootstrap, trees grown until pure.

    python3 bench/search/sklearn_compare.py FILE [--jobs N]
"""

import argparse
import time

import numpy as np
from sklearn.ensemble import RandomForestClassifier


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("csv")
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    labels, split, rows = [], [], []
    with open(args.csv) as f:
        for line in f:
            fields = line.rstrip("\n").split(",")
            labels.append(int(fields[0]))
            split.append(fields[1])
            rows.append([float(v) for v in fields[2:]])
    x = np.asarray(rows, dtype=np.float32)
    y = np.asarray(labels)
    test = np.asarray([s == "test" for s in split])
    forest = RandomForestClassifier(
        n_estimators=100,
        criterion="entropy",
        max_features=64,
        bootstrap=True,
        n_jobs=args.jobs,
        random_state=1,
    )
    start = time.perf_counter()
    forest.fit(x[~test], y[~test])
    fit_s = time.perf_counter() - start
    start = time.perf_counter()
    predicted = forest.predict(x[test])
    predict_s = time.perf_counter() - start
    accuracy = float(np.mean(predicted == y[test]))
    import sklearn

    print(
        f"| scikit-learn {sklearn.__version__} RandomForestClassifier "
        f"(100 trees, max_features=64, entropy, n_jobs={args.jobs}) "
        f"| {fit_s:.3f} | {predict_s:.4f} | {accuracy:.4f} |"
    )


if __name__ == "__main__":
    main()
