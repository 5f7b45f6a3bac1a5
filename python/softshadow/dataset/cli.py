"""The ``softshadow-dataset`` command (also ``python -m softshadow.dataset``).

``run SPEC --out DIR``: make the items of a spec (docs/dataset.md);
``check DIR``: report complete, missing and broken items. Exit codes: 0
success, 1 items failed or the storage failed (run) or items are
missing/broken (check), 2 a spec, an argument, the output folder or a
missing optional dependency (named with its extra) makes the command
unusable. Every number is checked against its range (:mod:`.limits`) by the
parser, before anything is read or written.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable

from . import limits as L


def _integer(lo: int, hi: int) -> Callable[[str], int]:
    """An argparse ``type`` for an integer in [lo, hi]: argparse prints
    "argument --window: must be an integer in [1, 100000], got -3" and exits
    with 2 (the range checked here too: a negative window once spun for ever)."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = None
        if value is None or not lo <= value <= hi:
            raise argparse.ArgumentTypeError(f"must be an integer in [{lo}, {hi}], got {text!r}")
        return value

    return parse


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="softshadow-dataset", description="Soft-shadow training data from a TOML spec.")
    sub = p.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run", help="make the items of a spec that --out lacks (resumes)")
    r.add_argument("spec", help="the spec file (TOML)")
    r.add_argument("--out", required=True, help="the output folder (created; one spec per folder)")
    r.add_argument(
        "--count",
        type=_integer(1, L.MAX_COUNT),
        help=f"items to have (default: the spec's count; at most {L.MAX_COUNT})",
    )
    r.add_argument("--items", help="make only these items, e.g. 0-9,15 (below the count)")
    r.add_argument(
        "--workers",
        type=_integer(1, L.MAX_WORKERS),
        default=1,
        help="local processes, or LocalCluster workers (default 1)",
    )
    r.add_argument(
        "--threads", type=_integer(1, L.MAX_THREADS), help="the core's threads per item (default: cores / workers)"
    )
    r.add_argument("--dask", help="'local' for a LocalCluster of --workers processes, or a scheduler address")
    r.add_argument(
        "--retries",
        type=_integer(0, L.MAX_RETRIES),
        default=2,
        help="attempts after the first for a failing item (default 2)",
    )
    r.add_argument(
        "--window", type=_integer(1, L.MAX_WINDOW), help="tasks in flight at once (default: 2 per worker thread)"
    )
    r.add_argument("--verify", action="store_true", help="re-hash the complete items and redo the broken ones")
    r.add_argument("--quiet", action="store_true", help="no progress bar")
    c = sub.add_parser("check", help="report complete, missing and broken items")
    c.add_argument("out", help="the output folder")
    c.add_argument("--no-hash", action="store_true", help="skip the sha256 comparison (faster)")
    return p


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    from .._extras import MissingExtraError
    from .fields import SpecError
    from .manifest import OutputError

    try:
        if args.command == "check":
            from .check import check_output, format_report

            report = check_output(args.out, hashes=not args.no_hash)
            print(format_report(report))
            return 0 if report.ok else 1
        from .manifest import StorageError
        from .runner import parse_items, run
        from .spec import load_spec

        spec = load_spec(args.spec)
        count = spec.count if args.count is None else args.count
        items = None if args.items is None else parse_items(args.items, count)
        try:
            summary = run(
                spec, args.out, count=count, items=items, workers=args.workers, threads=args.threads,
                dask=args.dask, retries=args.retries, window=args.window, verify=args.verify,
                progress=not args.quiet,
            )  # fmt: skip
        except StorageError as e:
            print(f"softshadow-dataset: error: {e}", file=sys.stderr)
            return 1
        print(summary)
        return 1 if summary.failed else 0
    except (SpecError, OutputError, ValueError, TypeError, MissingExtraError) as e:
        print(f"softshadow-dataset: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("softshadow-dataset: interrupted; rerun the same command to resume", file=sys.stderr)
        return 130
