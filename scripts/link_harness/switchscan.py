#!/usr/bin/env python3
"""Replays what a real terminal was sent (a `script -B -m advanced` recording that
terminals.py keeps as BASE.raw and BASE.timing) through pyte, frame by frame, to find frames
drawn from the wrong picture.

    python3 scripts/link_harness/switchscan.py BASE COLS ROWS [--paint SECONDS,...]

A shot at fixed seconds catches a one-frame defect only by luck (round 10 of
docs/terminals/right-pictures.md: serve's switch from sixel to cells drew the pool magnified
for one frame). This feeds the output to pyte up to each end of a synchronized update (sixel
images removed: pyte would print them as text), takes the picture rows' cell colours, and
prints every frame whose colours differ from the frame before by more than six times the
median difference (and at least 8 of 255 a channel on average): switches, stones and wrong
frames. With --paint, the frames within 0.15 s of each given second are written as ANSI text
(BASE-frame-SECONDS.ans) for ../shared/tools/ansi_view.py to paint. Needs pyte (pip).
"""

import argparse
import re
import statistics
import sys

try:
    import pyte
except ImportError:
    sys.exit("switchscan.py needs pyte: pip install pyte")

END = b"\x1b[?2026l"
SIXEL = re.compile(rb"\x1bP.*?\x1b\\", re.S)


def rgb(c):
    if isinstance(c, str) and len(c) == 6:
        try:
            return tuple(int(c[i:i + 2], 16) for i in (0, 2, 4))
        except ValueError:
            pass
    return (0, 0, 0)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("base")
    parser.add_argument("cols", type=int)
    parser.add_argument("rows", type=int)
    parser.add_argument("--paint", default="", help="seconds near which frames are written as ANSI")
    args = parser.parse_args()
    paint = [float(s) for s in args.paint.split(",") if s]
    raw = open(args.base + ".raw", "rb").read()
    lines = open(args.base + ".timing").read().split("\n")
    screen = pyte.Screen(args.cols, args.rows)
    stream = pyte.ByteStream(screen)

    def cells():
        return [rgb(ch.fg) + rgb(ch.bg) for y in range(args.rows - 1) for ch in (screen.buffer[y][x] for x in range(args.cols))]

    def write(at):
        with open("%s-frame-%.3f.ans" % (args.base, at), "w") as f:
            for y in range(args.rows):
                out = []
                for x in range(args.cols):
                    ch = screen.buffer[y][x]
                    out.append("\x1b[38;2;%d;%d;%dm\x1b[48;2;%d;%d;%dm%s" % (rgb(ch.fg) + rgb(ch.bg) + (ch.data or " ",)))
                f.write("".join(out) + "\x1b[0m\n")

    at, pos, pending, before, diffs, sixels = 0.0, raw.find(b"\n") + 1, b"", None, [], 0
    for line in lines:
        p = line.split()
        if len(p) < 3 or p[0] not in ("I", "O"):
            continue
        at += float(p[1])
        n = int(p[2])
        chunk = raw[pos:pos + n]
        pos += n
        if p[0] != "O":
            continue
        pending += chunk
        while END in pending:
            i = pending.index(END) + len(END)
            frame, pending = pending[:i], pending[i:]
            sixels += len(SIXEL.findall(frame))
            stream.feed(SIXEL.sub(b"", frame))
            now = cells()
            if before is not None:
                d = sum(abs(a - b) for u, v in zip(now, before) for a, b in zip(u, v)) / len(now) / 6
                diffs.append((at, d, sixels))
            before = now
            if any(t - 0.15 < at < t + 0.15 for t in paint):
                write(at)
    if not diffs:
        sys.exit("no synchronized frames in %s" % args.base)
    median = statistics.median(d for _, d, _ in diffs)
    print("frames %d, median difference %.2f, largest %.2f" % (len(diffs), median, max(d for _, d, _ in diffs)))
    for t, d, s in diffs:
        if d > max(8, 6 * median):
            print("  %.2f s: %.1f (sixel images so far %d)" % (t, d, s))


if __name__ == "__main__":
    main()
