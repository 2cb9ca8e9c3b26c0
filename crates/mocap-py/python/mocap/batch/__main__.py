"""``python -m mocap.batch clean|convert IN... -o OUT``: a batch on Ray.

Exit codes: 0 every take done, 1 bad input (nothing was processed),
3 some takes failed (listed in the manifest).
"""

from __future__ import annotations

import argparse
import sys
from typing import Optional, Sequence

from . import BatchError, clean, convert

EXIT_BAD_INPUT = 1
EXIT_SOME_FAILED = 3


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m mocap.batch",
        description="Clean or convert an archive of takes, one Ray task per take (docs/scale.md).",
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
    return p


def main(argv: Optional[Sequence[str]] = None) -> int:
    args = _parser().parse_args(argv)
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
