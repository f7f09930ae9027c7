"""Command line: ``python -m bgfn.data fetch`` resolves and verifies the NaveGo files and the RTKLIB drive's.

Prints, per file, where it was resolved from (``raw``, ``mirror``, ``download``) or why it is missing.
Exit status 0 when the required files (``ref.mat``, ``ekinox_gnss.mat``) are in ``data/raw``, 1 when one
of them cannot be had, 2 on a checksum mismatch or bad usage.
"""

from __future__ import annotations

import argparse
import logging
import sys

from bgfn.data.acquire import NAVEGO_TAG, failed_on, fetch_all, raw_files
from bgfn.errors import DataError


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``python -m bgfn.data``; returns the exit status."""
    parser = argparse.ArgumentParser(prog="python -m bgfn.data", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    fetch = sub.add_parser("fetch", help=f"resolve + verify the NaveGo {NAVEGO_TAG} files and the RTKLIB drive's "
                           "into data/raw")
    fetch.add_argument("--data-dir", default=None, help="data folder (default: $BGFN_DATA_DIR or <repo>/data)")
    fetch.add_argument("--mirror", default=None, help="mirror folder (default: $BGFN_DATA_MIRROR or "
                       "<repo>/../shared/data/navego)")
    fetch.add_argument("--rtklib-mirror", default=None, help="mirror folder of the RTKLIB drive (default: "
                       "$BGFN_RTKLIB_MIRROR or <repo>/../shared/data/rtklib-drive0708)")
    fetch.add_argument("--no-download", action="store_true", help="do not try the pinned URL")
    fetch.add_argument("--timeout", type=float, default=30.0, help="network timeout, s")
    fetch.add_argument("--retry", action="store_true", help="try again the downloads of optional files that failed "
                       "before (after one failure they are skipped)")
    fetch.add_argument("-v", "--verbose", action="store_true", help="also what was tried for an absent optional file")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.DEBUG if args.verbose else logging.INFO,
                        format="%(levelname)s %(name)s: %(message)s")
    try:
        resolved = fetch_all(data_dir=args.data_dir, mirror=args.mirror, rtklib_mirror=args.rtklib_mirror,
                             download=not args.no_download, timeout_s=args.timeout, retry=args.retry)
    except DataError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    status = 0
    absent: dict[str, list[str]] = {}        # optional files missing, by what stands in for them: one line each
    for res in resolved:
        spec = raw_files()[res.name]
        if res.path is not None:
            print(f"{res.name:18s} {res.origin:8s} {res.checksum}  <- {res.detail}")
        elif spec.required:
            print(f"{res.name:18s} REQUIRED, missing: {res.detail}")
            status = 1
        else:
            absent.setdefault(spec.when_missing, []).append(res.name)
    for when_missing, names in absent.items():
        failed = sorted({day for day in (failed_on(n, args.data_dir) for n in names) if day})
        skipped = (f"; its download failed on {', '.join(failed)} and is skipped since (to retry: python -m bgfn.data "
                   "fetch --retry)" if failed and not args.no_download else "")
        print(f"optional, absent: {', '.join(names)} -- {when_missing}{skipped} "
              "(what was tried: python -m bgfn.data fetch -v)")
    return status


if __name__ == "__main__":
    sys.exit(main())
