#!/usr/bin/env python3
"""Frames, bytes and CPU of `tidepool play --graphics MODE` per protocol, measured in a pty.

    python3 scripts/measure_graphics.py [SECONDS] [MODE...]     (default 10 s; all modes)

Not part of `cargo test`. Each mode runs `target/release/tidepool play pool --graphics MODE
--bandwidth unlimited --seed 1` (the player's default rain, so the water keeps moving) in a
160x48-cell pty with 8x16-pixel cells (TIOCGWINSZ's pixel fields: 1280x768). This script plays
the terminal: it answers the probe as xterm -ti vt340 with 256 colour registers does (and, for
`kitty-edits`, as kitty does for frame edits), answers every later device attributes question,
and reads everything at once (a terminal that is never the bottleneck). After a 2-second
warm-up it counts, over SECONDS: frames (synchronized-update markers), bytes, and the player's
CPU time (utime + stime from /proc/PID/stat), and prints one Markdown row per mode.
"""

import fcntl
import os
import select
import struct
import subprocess
import sys
import termios
import time

COLS, ROWS, CELL_W, CELL_H = 160, 48, 8, 16
WARM_UP = 2.0
TIDEPOOL = os.path.join(os.path.dirname(__file__), "..", "target", "release", "tidepool")
DA1_QUESTION = b"\x1b[c"
DA1_ANSWER = b"\x1b[?62;4;22c"
# xterm -ti vt340 -xrm 'XTerm*numColorRegisters: 256' -xrm 'XTerm*maxGraphicSize: 2000x2000'.
SIXEL_ANSWERS = b"\x1b[?1;0;256S\x1b[?2;0;2000;2000S"
# kitty's OK to the probe's graphics query (a forced protocol the answers rule out draws cells).
KITTY_OK = b"\x1b_Gi=31;OK\x1b\\"
# kitty's OK to the probe's frame-edit test (image id IMAGE_ID + 2).
KITTY_EDIT_OK = b"\x1b_Gi=7627890;OK\x1b\\"
SYNC_BEGIN = b"\x1b[?2026h"


def cpu_seconds(pid):
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def measure(mode, seconds):
    master, slave = os.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", ROWS, COLS, COLS * CELL_W, ROWS * CELL_H))
    env = {k: v for k, v in os.environ.items() if k not in ("TMUX", "SSH_CONNECTION", "SSH_TTY", "TERM_PROGRAM")}
    env.update(TERM="xterm-256color", COLORTERM="truecolor")
    graphics = "kitty" if mode == "kitty-edits" else mode

    def controlling_tty():
        os.setsid()
        fcntl.ioctl(0, termios.TIOCSCTTY, 0)

    child = subprocess.Popen(
        [TIDEPOOL, "play", "pool", "--graphics", graphics, "--bandwidth", "unlimited", "--seed", "1"],
        stdin=slave, stdout=slave, stderr=slave, env=env, preexec_fn=controlling_tty, close_fds=True)
    os.close(slave)
    asked = 0
    tail = b""
    start = time.monotonic()
    counting = False
    frames = total = 0
    cpu0 = t0 = None
    while True:
        now = time.monotonic()
        if not counting and now - start >= WARM_UP:
            counting, cpu0, t0 = True, cpu_seconds(child.pid), now
        if counting and now - t0 >= seconds:
            cpu = cpu_seconds(child.pid) - cpu0
            elapsed = now - t0
            break
        ready, _, _ = select.select([master], [], [], 0.05)
        if not ready:
            continue
        try:
            chunk = os.read(master, 1 << 20)
        except OSError:
            raise SystemExit(f"{mode}: the player ended early")
        data = tail + chunk
        for _ in range(data.count(DA1_QUESTION)):
            answer = DA1_ANSWER
            if asked == 0:
                kitty = KITTY_OK + (KITTY_EDIT_OK if mode == "kitty-edits" else b"")
                answer = (kitty if graphics == "kitty" else b"") + SIXEL_ANSWERS + DA1_ANSWER
            os.write(master, answer)
            asked += 1
        if counting:
            frames += data.count(SYNC_BEGIN) - tail.count(SYNC_BEGIN)
            total += len(chunk)
        tail = data[-16:]
    os.write(master, b"q")
    try:
        child.wait(timeout=5)
    except subprocess.TimeoutExpired:
        child.kill()
    os.close(master)
    fps = frames / elapsed
    return (f"| {mode} | {fps:.1f} | {total / elapsed / 1000:.0f} kB/s | "
            f"{total / max(frames, 1) / 1000:.1f} kB | {100 * cpu / elapsed:.0f}% |")


def main():
    seconds = float(sys.argv[1]) if len(sys.argv) > 1 else 10.0
    modes = sys.argv[2:] or ["cells", "sixel", "kitty", "kitty-edits", "iterm2"]
    print(f"160x48 cells of 8x16 pixels, {seconds:.0f} s after a {WARM_UP:.0f} s warm-up, load {os.getloadavg()[0]:.1f}")
    print("| mode | fps | bytes/s | bytes/frame | CPU (one core = 100%) |")
    print("| --- | ---: | ---: | ---: | ---: |")
    for mode in modes:
        print(measure(mode, seconds), flush=True)


if __name__ == "__main__":
    main()
