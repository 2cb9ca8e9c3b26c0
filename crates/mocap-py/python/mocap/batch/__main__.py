"""``python -m mocap.batch clean|convert|index IN... -o OUT``: a batch on Ray.

Exit codes: 0 every take done, 1 bad input (nothing was processed),
3 some takes failed (listed in the manifest).
"""

from __future__ import annotations

import argparse
import sys
from typing import Optional, Sequence

from . import BatchError, clean, convert, index

EXIT_BAD_INPUT = 1
EXIT_SOME_FAILED = 3


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m mocap.batch",
        description="Clean, convert or index an archive of takes, one Ray task per take (docs/scale.md).",
    )
    sub = p.add_subparsers(dest="command", required=True)

    def common(sp: argparse.ArgumentParser) -> None:
        sp.add_argument(
            "inputs", nargs="+", metavar="IN",
            help="a folder (its .bvh and .amc files, recursively), a glob, a take or a list file",
        )
        sp.add_argument("-o", "--output", required=True, metavar="OUT",
                        help="the output folder (mirrors the input tree)")
        sp.add_argument("--address", default=None, metavar="ADDR",
                        help="local (default), auto, HOST:PORT or ray://HOST:PORT")
        sp.add_argument("--manifest", default=None, metavar="FILE",
                        help="the JSON-lines manifest (default OUT/manifest.jsonl)")
        sp.add_argument("--num-cpus", type=int, default=None, metavar="N",
                        help="CPUs of a local Ray (default: all)")
        sp.add_argument("--max-retries", type=int, default=3, metavar="N",
                        help="retries of a take whose worker or node died (default 3)")
        sp.add_argument("--no-resume", action="store_true",
                        help="redo takes the manifest says are done")
        sp.add_argument("-q", "--quiet", action="store_true", help="no progress lines")

    c = sub.add_parser("clean", help="clean every take (as mocap clean apply)")
    common(c)
    c.add_argument("--model", default=None, metavar="FILE",
                   help="a model file (default: the shipped model)")
    c.add_argument("--filter", default=None, metavar="SPEC",
                   help="a classical filter instead of a model (butterworth:2:6, ...)")

    v = sub.add_parser("convert", help="convert every take to BVH or glTF")
    common(v)
    v.add_argument("--to", choices=["bvh", "glb", "gltf"], required=True)
    v.add_argument("--fps", type=float, default=None, help="resample to this frame rate")
    v.add_argument("--mirror", action="store_true", help="swap left and right")

    x = sub.add_parser("index", help="build a search index (as mocap search index)")
    x.add_argument("inputs", nargs="+", metavar="IN", help="clip files and folders")
    x.add_argument("-o", "--output", required=True, metavar="INDEX", help="the index file")
    x.add_argument("--labels", default=None, metavar="FILE", help="a CSV/TSV of path,label[,performer]")
    x.add_argument("--labels-from-name", default=None, metavar="PATTERN",
                   help="a file-name pattern or preset (bandai-content, ...)")
    x.add_argument("--trees", type=int, default=100)
    x.add_argument("--candidates", type=int, default=64)
    x.add_argument("--min-entropy", type=float, default=0.0)
    x.add_argument("--frames", type=int, default=10)
    x.add_argument("--seed", type=int, default=1)
    x.add_argument("--no-bootstrap", action="store_true")
    x.add_argument("--address", default=None, metavar="ADDR",
                   help="local (default), auto, HOST:PORT or ray://HOST:PORT")
    x.add_argument("--num-cpus", type=int, default=None, metavar="N")
    x.add_argument("-q", "--quiet", action="store_true", help="no progress lines")
    return p


def main(argv: Optional[Sequence[str]] = None) -> int:
    args = _parser().parse_args(argv)
    if args.command == "index":
        try:
            result = index(
                args.inputs, args.output, labels=args.labels,
                labels_from_name=args.labels_from_name, trees=args.trees,
                candidates=args.candidates, min_entropy=args.min_entropy, frames=args.frames,
                seed=args.seed, bootstrap=not args.no_bootstrap, address=args.address,
                progress=not args.quiet, num_cpus=args.num_cpus,
            )
        except BatchError as e:
            print(f"error: {e}", file=sys.stderr)
            return EXIT_BAD_INPUT
        print(f"indexed {result.done} of {result.total} clips into {args.output}"
              f" in {result.seconds:.1f} s; manifest {result.manifest}")
        for source, error in result.errors[:10]:
            print(f"failed: {source}: {error}", file=sys.stderr)
        return EXIT_SOME_FAILED if result.failed else 0
    common = dict(
        address=args.address, manifest=args.manifest, progress=not args.quiet,
        num_cpus=args.num_cpus, max_retries=args.max_retries, resume=not args.no_resume,
    )
    try:
        if args.command == "clean":
            result = clean(args.inputs, args.output, model=args.model, filter=args.filter, **common)
        else:
            result = convert(args.inputs, args.output, to=args.to, fps=args.fps,
                             mirror=args.mirror, **common)
    except BatchError as e:
        print(f"error: {e}", file=sys.stderr)
        return EXIT_BAD_INPUT
    print(
        f"{result.done} done, {result.skipped} skipped as done before, {result.failed} failed"
        f" of {result.total} takes in {result.seconds:.1f} s; manifest {result.manifest}"
    )
    for source, error in result.errors[:10]:
        print(f"failed: {source}: {error}", file=sys.stderr)
    if len(result.errors) > 10:
        print(f"... and {len(result.errors) - 10} more (see the manifest)", file=sys.stderr)
    return EXIT_SOME_FAILED if result.failed else 0


if __name__ == "__main__":
    sys.exit(main())
