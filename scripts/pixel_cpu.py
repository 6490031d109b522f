#!/usr/bin/env python3
"""Whole-process CPU of `tidepool play` per picture mode, measured in a pseudo-terminal that
answers like the terminal each mode is for.

    python3 scripts/pixel_cpu.py [--seconds 6] [--warm-up 2] [--rounds 3]
        [--scenes pool,ocean,lake] [--modes cells,kitty,kitty-direct,iterm2,sixel]
        [--bin LABEL=PATH ...] [--sixel-fps 15] [--bandwidth unlimited]

Not part of `cargo test` (a measurement, never a timed test). Each run starts
`PATH play SCENE --graphics MODE --bandwidth unlimited --seed 1` (`--bandwidth` as given: a
fixed link rate such as 250k measures the encoders that run under a rate, kitty-direct's lossy
PNG and iTerm2's JPEG; kitty's temporary files carry raw pixels at any rate; the player's defaults
otherwise: for the pool a grid of two cells a pixel, gusts, caustics) in a pty of 160x48 cells
of 8x16 pixels (TIOCGWINSZ's pixel fields: 1280x768), as a session leader with the pty as its
controlling terminal. This script plays the terminal, answering the probe as the terminal of
the mode would, and every later device-attributes question (the link's round trip):

- cells: an xterm without sixel (DA1 only);
- kitty: kitty 0.26 on this machine: the graphics query, the temporary-file query and the
  frame-edit probe answered OK (so the player sends frames through files in /dev/shm, which
  this script deletes as kitty does once it has read them);
- kitty-direct: the same without the file answer (pixels in band, zlib and base64, as over SSH);
- iterm2: iTerm2's cell-size reply (and TERM_PROGRAM=iTerm.app);
- sixel: xterm -ti vt340 with 256 colour registers and a 2000x2000 largest image, shown at
  `--sixel-fps` pictures a second (`--fps`; 15 by default: sixel's target rate).

It reads everything at once (a terminal that is never the bottleneck). After the warm-up it
counts, over SECONDS: the process's CPU time (utime + stime of /proc/PID/stat: every thread,
user and system), pictures (kitty transmit or frame-edit commands, sixel images, iTerm2
files), frames (synchronized-update markers) and bytes. Runs are interleaved round by round
(every scene, mode and binary in turn), so binaries compared in one call see the same load;
the table gives each one's median over the rounds, every round's figure, and the load average
before and after.
"""

import argparse
import base64
import fcntl
import os
import re
import select
import statistics
import struct
import subprocess
import sys
import termios
import time

COLS, ROWS, CELL_W, CELL_H = 160, 48, 8, 16
HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_BIN = os.path.join(HERE, "..", "target", "release", "tidepool")

DA1_QUESTION = b"\x1b[c"
DA1_PLAIN = b"\x1b[?62;22c"
# tidepool's kitty image id (src/output/graphics/kitty.rs) and the probe's ids after it.
IMAGE_ID = 0x0074_6470
KITTY_OK = lambda image_id: b"\x1b_Gi=%d;OK\x1b\\" % image_id  # noqa: E731
PROBE_ANSWERS = {
    "cells": DA1_PLAIN,
    "kitty": KITTY_OK(31) + KITTY_OK(IMAGE_ID + 1) + KITTY_OK(IMAGE_ID + 2) + b"\x1b[?2026;2$y" + DA1_PLAIN,
    "kitty-direct": KITTY_OK(31) + KITTY_OK(IMAGE_ID + 2) + b"\x1b[?2026;2$y" + DA1_PLAIN,
    "iterm2": b"\x1b]1337;ReportCellSize=16.0;8.0;1.0\x1b\\" + DA1_PLAIN,
    "sixel": b"\x1b[?1;0;256S\x1b[?2;0;2000;2000S\x1b[?62;4;22c",
}
GRAPHICS_FLAG = {"cells": "cells", "kitty": "kitty", "kitty-direct": "kitty", "iterm2": "iterm2", "sixel": "sixel"}
PICTURE = {
    "cells": None,
    "kitty": re.compile(rb"\x1b_G(?:[^;\x1b]*,)?a=[Tf][,;]"),
    "kitty-direct": re.compile(rb"\x1b_G(?:[^;\x1b]*,)?a=[Tf][,;]"),
    "iterm2": re.compile(rb"\x1b\]1337;File="),
    "sixel": re.compile(rb"\x1bP[0-9;]*q"),
}
# A kitty command that names a temporary file (t=t): its payload is the path in base64.
TEMP_FILE = re.compile(rb"\x1b_G([^;\x1b]{0,400});([A-Za-z0-9+/=]{1,800})\x1b\\")
TEMP_FILE_MARKER = b"tty-graphics-protocol"
SYNC_BEGIN = b"\x1b[?2026h"
TAIL = 2048


def cpu_seconds(pid):
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def count_new(pattern, data, old):
    """Matches in `data` that end past its first `old` bytes (those were counted before)."""
    return sum(1 for m in pattern.finditer(data) if m.end() > old)


def delete_temp_files(data, old):
    """Deletes the files kitty would read and delete (commands with t=t ending past `old`)."""
    for m in TEMP_FILE.finditer(data):
        if m.end() <= old or b"t=t" not in m.group(1).split(b","):
            continue
        try:
            path = base64.b64decode(m.group(2))
        except ValueError:
            continue
        if TEMP_FILE_MARKER in path:
            try:
                os.unlink(path)
            except OSError:
                pass


def run(binary, scene, mode, args):
    master, slave = os.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", ROWS, COLS, COLS * CELL_W, ROWS * CELL_H))
    hidden = ("TMUX", "SSH_CONNECTION", "SSH_CLIENT", "SSH_TTY", "TERM_PROGRAM", "KITTY_WINDOW_ID")
    env = {k: v for k, v in os.environ.items() if k not in hidden}
    env.update(TERM="xterm-256color", COLORTERM="truecolor")
    if mode == "iterm2":
        env["TERM_PROGRAM"] = "iTerm.app"
    command = [binary, "play", scene, "--graphics", GRAPHICS_FLAG[mode], "--bandwidth", args.bandwidth, "--seed", "1"]
    if mode == "sixel":
        command += ["--fps", str(args.sixel_fps)]

    def controlling_tty():
        os.setsid()
        fcntl.ioctl(0, termios.TIOCSCTTY, 0)

    child = subprocess.Popen(command, stdin=slave, stdout=slave, stderr=slave, env=env,
                             preexec_fn=controlling_tty, close_fds=True)
    os.close(slave)
    asked, tail = 0, b""
    start = time.monotonic()
    counting = False
    frames = pictures = total = 0
    cpu0 = t0 = None
    picture = PICTURE[mode]
    try:
        while True:
            now = time.monotonic()
            if not counting and now - start >= args.warm_up:
                counting, cpu0, t0 = True, cpu_seconds(child.pid), now
            if counting and now - t0 >= args.seconds:
                cpu, elapsed = cpu_seconds(child.pid) - cpu0, now - t0
                break
            ready, _, _ = select.select([master], [], [], 0.05)
            if not ready:
                continue
            try:
                chunk = os.read(master, 1 << 20)
            except OSError:
                raise SystemExit(f"{binary} {scene} {mode}: the player ended early (status {child.poll()})")
            data, old = tail + chunk, len(tail)
            for _ in range(count_new(re.compile(re.escape(DA1_QUESTION)), data, old)):
                os.write(master, PROBE_ANSWERS[mode] if asked == 0 else DA1_PLAIN)
                asked += 1
            # kitty deletes what it reads; other terminals ignore the probe's file query, whose
            # file this script deletes too, so that runs leave nothing behind.
            delete_temp_files(data, old)
            if counting:
                frames += data.count(SYNC_BEGIN) - tail.count(SYNC_BEGIN)
                if picture is not None:
                    pictures += count_new(picture, data, old)
                total += len(chunk)
            tail = data[-TAIL:]
    finally:
        try:
            os.write(master, b"q")
            child.wait(timeout=5)
        except (OSError, subprocess.TimeoutExpired):
            child.kill()
            child.wait()
        os.close(master)
    return {"cpu": 100 * cpu / elapsed, "frames": frames / elapsed, "pictures": pictures / elapsed,
            "kbps": total / elapsed / 1000}


def load():
    return "{:.2f} {:.2f} {:.2f}".format(*os.getloadavg())


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=6.0)
    parser.add_argument("--warm-up", type=float, default=2.0)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--scenes", default="pool")
    parser.add_argument("--modes", default="cells,kitty,kitty-direct,iterm2,sixel")
    parser.add_argument("--sixel-fps", type=int, default=15)
    parser.add_argument("--bandwidth", default="unlimited",
                        help="the player's --bandwidth: unlimited or a rate such as 250k or 2M (default: unlimited)")
    parser.add_argument("--bin", action="append", default=[], metavar="LABEL=PATH",
                        help="a binary to measure (repeat to compare; default: this=target/release/tidepool)")
    args = parser.parse_args()
    if not (0 < args.seconds <= 600 and 0 <= args.warm_up <= 60 and 1 <= args.rounds <= 50):
        sys.exit("pixel_cpu.py: --seconds must be in (0, 600], --warm-up in [0, 60], --rounds in 1..=50")
    if not re.fullmatch(r"unlimited|[0-9]{1,12}(\.[0-9]{1,6})?[kKmM]?", args.bandwidth):
        sys.exit(f"pixel_cpu.py: --bandwidth {args.bandwidth!r} is not unlimited or a rate such as 250k")
    binaries = []
    for item in args.bin or [f"this={DEFAULT_BIN}"]:
        label, sep, path = item.partition("=")
        if not sep or not os.access(path, os.X_OK):
            sys.exit(f"pixel_cpu.py: --bin {item!r} is not LABEL=PATH of an executable; build it first")
        binaries.append((label, path))
    scenes = [s for s in args.scenes.split(",") if s]
    modes = [m for m in args.modes.split(",") if m]
    for m in modes:
        if m not in PROBE_ANSWERS:
            sys.exit(f"pixel_cpu.py: unknown mode {m!r}; choose from {', '.join(PROBE_ANSWERS)}")
    print(f"{COLS}x{ROWS} cells of {CELL_W}x{CELL_H} px, --bandwidth {args.bandwidth}, {args.seconds:g} s after a "
          f"{args.warm_up:g} s warm-up, {args.rounds} rounds; sixel at --fps {args.sixel_fps}; "
          f"load average before: {load()}", flush=True)
    results = {}
    for r in range(args.rounds):
        for scene in scenes:
            for mode in modes:
                for label, path in binaries:
                    res = run(path, scene, mode, args)
                    results.setdefault((scene, mode, label), []).append(res)
                    print(f"  round {r + 1}: {scene} {mode} {label}: {res['cpu']:.1f} % CPU, "
                          f"{res['pictures']:.1f} pictures/s, {res['frames']:.1f} frames/s (load {load()})",
                          file=sys.stderr, flush=True)
    print(f"load average after: {load()}")
    print()
    print("| scene | mode | binary | CPU, % of one core (median) | rounds | pictures/s | frames/s | kB/s |")
    print("| --- | --- | --- | ---: | --- | ---: | ---: | ---: |")
    for (scene, mode, label), runs in results.items():
        med = lambda key: statistics.median(x[key] for x in runs)  # noqa: E731
        rounds = " ".join(f"{x['cpu']:.0f}" for x in runs)
        pictures = f"{med('pictures'):.1f}" if PICTURE[mode] is not None else "-"
        print(f"| {scene} | {mode} | {label} | {med('cpu'):.1f} | {rounds} | {pictures} | "
              f"{med('frames'):.1f} | {med('kbps'):.0f} |")


if __name__ == "__main__":
    main()
