"""Reading the JSON reports of `mocap style eval --json` for the table scripts of
bench/style (asymmetry_table.py, judges_table.py): one method's row of one
set, and figures pooled over several reports by their number of pairs."""
import json
import pathlib


def method_row(report, data_set, method):
    """The row of `method` in the set `data_set` of a report (a parsed
    report, or the path of its JSON file)."""
    if isinstance(report, pathlib.Path):
        report = json.loads(report.read_text())
    s = next(x for x in report["sets"] if x["set"] == data_set)
    return next(x for x in s["methods"] if x["method"] == method)


def pooled(rows, key):
    """`key` over all the pairs of `rows` (their mean weighted by pairs)."""
    return sum(r[key] * r["pairs"] for r in rows) / sum(r["pairs"] for r in rows)
