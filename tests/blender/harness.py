"""What the Blender checks share: their command line after Blender's `--`
(pairs of a file and its positions JSON, `--tolerance M`, `--report FILE`),
and running a check on every pair, printing one result line each, writing
the report and exiting 1 when any failed."""

import json
import sys

import bpy


def parse_arguments(argv, kind):
    args = argv[argv.index("--") + 1:] if "--" in argv else []
    tolerance = 1e-3
    report = None
    files = []
    i = 0
    while i < len(args):
        if args[i] == "--tolerance":
            tolerance = float(args[i + 1])
            i += 2
        elif args[i] == "--report":
            report = args[i + 1]
            i += 2
        else:
            files.append(args[i])
            i += 1
    if not files or len(files) % 2:
        raise SystemExit(f"expected pairs of {kind} file and positions JSON after --")
    return list(zip(files[0::2], files[1::2])), tolerance, report


def run_checks(check, kind, prefix):
    """`check(file, positions, tolerance)` returns a result dict with
    `file` and `passed`."""
    pairs, tolerance, report = parse_arguments(sys.argv, kind)
    results = [check(f, p, tolerance) for f, p in pairs]
    for r in results:
        print(f"{prefix} " + json.dumps(r))
    if report:
        with open(report, "w") as f:
            json.dump({"blender": bpy.app.version_string, "results": results}, f, indent=1)
    failed = [r["file"] for r in results if not r.get("passed")]
    if failed:
        print(f"{prefix} failed: " + ", ".join(failed))
        sys.exit(1)
