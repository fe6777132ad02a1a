#!/usr/bin/env python3
"""Check that files are complete PNG images of a useful size.

usage: check_png.py [--min-px N] [--newer-than REF] FILE.png [...]

Each file must exist, be nonempty, start with the PNG signature, hold an
IHDR chunk first and an IEND chunk last with every chunk's CRC intact, and
be more than N pixels (default 100) wide and high.  With --newer-than, each
must also be at least as new as REF, so a stale image from an earlier run
does not pass.  Standard library only.  Exit 0 when all pass, else 1.
"""

import argparse
import struct
import sys
import zlib
from pathlib import Path

SIGNATURE = b"\x89PNG\r\n\x1a\n"


def png_problem(path, min_px, newer_than):
    """None when path is a good PNG, else what is wrong with it."""
    if not path.is_file():
        return "missing"
    data = path.read_bytes()
    if not data:
        return "empty"
    if not data.startswith(SIGNATURE):
        return "no PNG signature"
    pos, chunks = len(SIGNATURE), []
    while pos < len(data):
        if pos + 12 > len(data):
            return "truncated chunk header"
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        end = pos + 12 + length
        if end > len(data):
            return f"truncated {kind!r} chunk"
        (crc,) = struct.unpack(">I", data[end - 4:end])
        if zlib.crc32(data[pos + 4:end - 4]) != crc:
            return f"bad CRC in {kind!r} chunk"
        chunks.append((kind, data[pos + 8:end - 4]))
        pos = end
    if not chunks or chunks[0][0] != b"IHDR" or chunks[-1][0] != b"IEND":
        return "chunks do not run IHDR ... IEND"
    if not any(kind == b"IDAT" for kind, _ in chunks):
        return "no image data"
    width, height = struct.unpack(">II", chunks[0][1][:8])
    if width <= min_px or height <= min_px:
        return f"only {width} x {height} px (need more than {min_px})"
    if newer_than and path.stat().st_mtime_ns < newer_than.stat().st_mtime_ns:
        return f"older than {newer_than} (left from an earlier run?)"
    print(f"{path}: PNG {width} x {height} px, {len(data)} bytes")
    return None


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("files", nargs="+", type=Path, metavar="FILE.png")
    parser.add_argument("--min-px", type=int, default=100)
    parser.add_argument("--newer-than", type=Path, metavar="REF")
    args = parser.parse_args()
    if args.newer_than and not args.newer_than.exists():
        parser.error(f"{args.newer_than}: no such file")
    bad = 0
    for path in args.files:
        problem = png_problem(path, args.min_px, args.newer_than)
        if problem:
            print(f"{path}: {problem}", file=sys.stderr)
            bad += 1
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
